//! The method's GPU state and passes (shaders/termination.wgsl): the hashed grid of
//! records, the propagation dispatch, the tracer with the termination decision, the insertion
//! of new keys and the vertex store. One frame = propagate, fold, trace, insert, store
//! ([`TcPass`]), each its own timed pass, in three submissions: [`TerminationCache::update`]
//! (propagate, fold: the records the image reads), [`TerminationCache::trace`] (the image),
//! [`TerminationCache::store`] (after the image: the keys and vertices the next frame
//! propagates). Rules of one cache key share the cache: each has a [`TerminationTracer`] and
//! runs only the trace ([`TerminationCache::trace_with`]).
//!
//! Deterministic: the same scene, seed and settings give the same bits on any adapter. Sums are
//! per invocation or integer atomics; a record's stored vertex and a new key's slot are each
//! the lowest candidate index that asked for them (atomicMin), the slot settled in rounds of
//! claim and win ([`INSERT_ROUNDS`]).

mod dispatch;
mod frame;
mod gpu_types;
mod output;
mod passes;
mod program;
mod readback;
mod statistics;
mod trace;
mod tracer;

pub use gpu_types::{TcParams, TcRecord, TcVertex};
pub use output::TerminationOutput;
pub use passes::{
    INSERT_ROUNDS, TC_FOLD_PASS, TC_INSERT_PASS, TC_PROPAGATE_PASS, TC_STORE_PASS, TC_TRACE_PASS,
    TcPass,
};
pub use statistics::{CacheStatistics, TerminationStats};
pub use tracer::TerminationTracer;

use super::settings::{TerminationSettings, VERTICES_PER_RECORD};
use gpu_types::OWN_GROUP;
use hash_cache::HashCacheParams;
use passes::{ENTRY_POINTS, INSERT_WORKGROUP};
use render::error::RenderError;
use render::frame_bindings::FrameBindings;
use render::gpu::Gpu;
use render::scene_gpu::SceneGpu;
use render::timing::PassTimer;
use taa::TaaPrimary;
use tracer::{SharedBuffers, build_tracer};

pub struct TerminationCache {
    settings: TerminationSettings,
    width: u32,
    height: u32,
    hc: wgpu::Buffer,
    slots: wgpu::Buffer,
    records: wgpu::Buffer,
    vertices: wgpu::Buffer,
    inserts: wgpu::Buffer,
    /// The insertion passes' workgroups, copied from `inserts` (a buffer bound as storage
    /// cannot be a dispatch's indirect buffer).
    insert_args: wgpu::Buffer,
    frame: FrameBindings,
    layout: wgpu::BindGroupLayout,
    /// The cache's own tracer (the settings it was built with): its group binds every pass but
    /// other rules' traces, its counters count them, and it traces the warm-up frames.
    own: TerminationTracer,
    /// This frame's parameters of the cache's passes, from which each tracer's are made.
    frame_params: TcParams,
    /// Indexed as [`ENTRY_POINTS`].
    pipelines: [render::pass_library::LibraryPipeline; 7],
    /// One timer per submission: [`TcPass::UPDATE`], [`TcPass::STORE`] (each tracer times its
    /// own trace).
    update_timer: PassTimer,
    store_timer: PassTimer,
    /// Frames (warm-up included) run so far.
    frames: u32,
    /// `RadianceScale::CacheMean`'s unit: the mean luminance over the filled records the first
    /// image reads (set by the first [`Self::update`], then fixed for the run).
    derived_unit: Option<f64>,
}

impl TerminationCache {
    /// Builds the cache; refuses a capacity or resolution over the adapter's buffer limits.
    pub fn new(
        gpu: &Gpu,
        scene: &SceneGpu,
        settings: TerminationSettings,
    ) -> Result<Self, RenderError> {
        settings.validate()?;
        let s = scene.settings();
        let (width, height) = (s.width, s.height);
        let pixels = width as u64 * height as u64;
        let cap = settings.capacity as u64;
        gpu.check_resolution(
            width,
            height,
            size_of::<TaaPrimary>() as u64 + 16 + 4 + size_of::<TcVertex>() as u64,
        )?;
        gpu.check_buffer_size(
            "termination cache records (moments + vertex estimates)",
            cap * (1 + VERTICES_PER_RECORD) * size_of::<TcRecord>() as u64,
        )?;
        gpu.check_buffer_size(
            "termination cache vertices (stored + candidates)",
            (cap * 2 * VERTICES_PER_RECORD + pixels) * 32,
        )?;
        // One request at most per candidate (pixel or propagated vertex).
        let requests = pixels + cap * VERTICES_PER_RECORD;
        gpu.check_buffer_size("termination insertion requests", 16 + 16 * requests)?;
        let insert_groups = requests.div_ceil(INSERT_WORKGROUP);
        let max_groups = gpu.limits.max_compute_workgroups_per_dimension as u64;
        if insert_groups > max_groups {
            return Err(RenderError::Settings(format!(
                "termination cache: {requests} candidates (pixels + 4 x capacity) need {insert_groups} workgroups of {INSERT_WORKGROUP} for insertion, over the adapter's {max_groups}"
            )));
        }
        gpu.check_workgroup_memory(TC_TRACE_PASS, 0)?;
        let device = &gpu.device;
        let buffer = |label: &str, size: u64, usage: wgpu::BufferUsages| {
            device.create_buffer(&wgpu::BufferDescriptor {
                label: Some(label),
                size,
                usage,
                mapped_at_creation: false,
            })
        };
        let rw = wgpu::BufferUsages::STORAGE
            | wgpu::BufferUsages::COPY_SRC
            | wgpu::BufferUsages::COPY_DST;
        let parameters = wgpu::BufferUsages::STORAGE | wgpu::BufferUsages::COPY_DST;
        let hc = buffer("termination hc", size_of::<HashCacheParams>() as u64, parameters);
        let slots = buffer("termination slots", cap * 16, rw);
        // Empty slots with no claims (claim = NONE).
        let empty: Vec<[u32; 4]> = vec![[0, u32::MAX, 0, u32::MAX]; cap as usize];
        gpu.queue.write_buffer(&slots, 0, bytemuck::cast_slice(&empty));
        let records = buffer(
            "termination records",
            cap * (1 + VERTICES_PER_RECORD) * size_of::<TcRecord>() as u64,
            rw,
        );
        let vertices =
            buffer("termination vertices", (cap * 2 * VERTICES_PER_RECORD + pixels) * 32, rw);
        let inserts = buffer("termination insertion requests", 16 + 16 * requests, rw);
        let insert_args = buffer(
            "termination insertion dispatch",
            12,
            wgpu::BufferUsages::INDIRECT | wgpu::BufferUsages::COPY_DST,
        );
        let (layout, pipelines) = scene.library_pass(
            gpu,
            "termination.wgsl",
            Self::program(),
            &OWN_GROUP,
            ENTRY_POINTS,
        )?;
        let shared = SharedBuffers {
            hc: &hc,
            slots: &slots,
            records: &records,
            vertices: &vertices,
            inserts: &inserts,
        };
        let own = build_tracer(gpu, &layout, shared, settings, true, pixels);
        Ok(Self {
            settings,
            width,
            height,
            hc,
            slots,
            records,
            vertices,
            inserts,
            insert_args,
            frame: FrameBindings::new(gpu, scene),
            own,
            layout,
            frame_params: bytemuck::Zeroable::zeroed(),
            pipelines,
            update_timer: PassTimer::new(gpu, &TcPass::UPDATE.map(TcPass::name)),
            store_timer: PassTimer::new(gpu, &TcPass::STORE.map(TcPass::name)),
            frames: 0,
            derived_unit: None,
        })
    }

    /// A tracer for another rule over this cache; refused unless `settings` has this cache's
    /// [`TerminationSettings::cache_key`] (only then are its records the ones it would build
    /// alone). `offers`: whether its primary vertices are offered to the records; exactly one
    /// tracer a frame must offer them (the plugin: the cache's first method).
    pub fn tracer(
        &self,
        gpu: &Gpu,
        settings: TerminationSettings,
        offers: bool,
    ) -> Result<TerminationTracer, RenderError> {
        settings.validate()?;
        if settings.cache_key() != self.settings.cache_key() {
            return Err(RenderError::Settings(format!(
                "termination cache: a tracer with settings {settings:?} cannot share the cache of {:?} (only the rule, survival and radiance unit may differ, and path tracing shares only with path tracing)",
                self.settings
            )));
        }
        let shared = SharedBuffers {
            hc: &self.hc,
            slots: &self.slots,
            records: &self.records,
            vertices: &self.vertices,
            inserts: &self.inserts,
        };
        let pixels = self.width as u64 * self.height as u64;
        Ok(build_tracer(gpu, &self.layout, shared, settings, offers, pixels))
    }

    pub fn settings(&self) -> TerminationSettings {
        self.settings
    }

    /// Bytes of the cache (records × bytes per record), as checked against the adapter.
    pub fn cache_bytes(&self) -> u64 {
        self.settings.cache_bytes()
    }
}
