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

use super::gpu_decision::{decision_module, rule_words};
use super::moments::RecordMoments;
use super::rule::TerminationRule;
use super::settings::{
    BYTES_PER_RECORD, Incomplete, RadianceScale, TerminationSettings, VERTICES_PER_RECORD,
};
use glam::Vec3;
use hash_cache::{HashCacheParams, HashCacheSettings};
use render::compute::{self, BufferBinding};
use render::error::RenderError;
use render::frame_bindings::FrameBindings;
use render::gpu::Gpu;
use render::gpu_struct::GpuStruct;
use render::lights::luminance;
use render::pass_library::PassLibrary;
use render::readback::{copy_all, read_pod};
use render::scene::Camera;
use render::scene_gpu::SceneGpu;
use render::shader::{Module, Program};
use render::timing::{PassTimer, PassTiming};
use taa::TaaPrimary;

pub const TC_PROPAGATE_PASS: &str = "tc_propagate";
pub const TC_FOLD_PASS: &str = "tc_fold";
pub const TC_TRACE_PASS: &str = "tc_trace";
pub const TC_STORE_PASS: &str = "tc_store";
/// The insertion of the frame's new keys: [`INSERT_ROUNDS`] claim and win dispatches and one
/// settle dispatch, timed as one pass.
pub const TC_INSERT_PASS: &str = "tc_insert";
/// During the warm-up a record averages only its last few estimates: the propagation is an
/// iteration from an empty cache, and its early, darker values must not linger.
const WARMUP_MAX_VERTICES: u32 = 4;
/// Words of `counters` (termination.wgsl's TC_COUNTER_*).
const COUNTERS: u64 = 10;
/// Words of `counters` a trace writes (path vertices, trace rays, unknown records): a tracer's
/// own; every other word counts the cache's passes.
const TRACE_COUNTERS: [u64; 3] = [0, 1, 6];
/// Pass names, in the order of [`TcPass`].
const PASSES: [&str; 5] =
    [TC_PROPAGATE_PASS, TC_FOLD_PASS, TC_TRACE_PASS, TC_INSERT_PASS, TC_STORE_PASS];
/// Entry points (indices of the pipelines): one per pass of [`PASSES`] but the insertion, whose
/// three follow.
const ENTRY_POINTS: [&str; 7] = [
    TC_PROPAGATE_PASS,
    TC_FOLD_PASS,
    TC_TRACE_PASS,
    TC_STORE_PASS,
    "tc_insert_claim",
    "tc_insert_win",
    "tc_insert_settle",
];
/// Rounds of claim and win per frame: a request whose claim loses to another key's this many
/// times fails, as one whose probe window is full does (both counted in `insert_failures`).
/// A request loses a round only to another new key claiming the same empty slot in the same
/// frame, so rounds beyond a few settle nothing: at most the probe window's length are needed.
pub const INSERT_ROUNDS: u32 = 8;
/// Threads per workgroup of the insertion passes (`TC_INSERT_WORKGROUP`).
const INSERT_WORKGROUP: u64 = 256;
/// Header words of `inserts` (indirect workgroups x, y, z; the request count).
const INSERT_HEADER: [u32; 4] = [0, 1, 1, 0];

/// The cache's passes in frame order; each is timed under its name (frames.csv's column).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum TcPass {
    /// Per stored vertex: new estimates at the stored vertices.
    Propagate,
    /// Per record: the estimates folded into the record's moments.
    Fold,
    /// Per pixel: the image, the rule deciding at every vertex over the folded records.
    Trace,
    /// Per insertion request (a candidate vertex whose key has no slot): new keys get slots.
    Insert,
    /// Per record: the winning candidate becomes a stored vertex, for the next frame.
    Store,
}

impl TcPass {
    /// The passes before the image, in one submission.
    pub const UPDATE: [TcPass; 2] = [TcPass::Propagate, TcPass::Fold];
    /// The passes after the image, in one submission.
    pub const STORE: [TcPass; 2] = [TcPass::Insert, TcPass::Store];

    pub fn name(self) -> &'static str {
        PASSES[self as usize]
    }
}

const OWN_GROUP: [BufferBinding; 10] = [
    // The hash cache's parameters: its voxel keys (capacity, probe limit, LOD, jitter).
    BufferBinding::read("hc", "HashCacheParams"),
    BufferBinding::read("tc", "TcParams"),
    BufferBinding::read_write("slots", "array<atomic<u32>>"),
    BufferBinding::read_write("records", "array<TcRecord>"),
    BufferBinding::read_write("vertices", "array<TcVertex>"),
    BufferBinding::read_write("counters", "array<atomic<u32>>"),
    BufferBinding::read_write("primary_out", "array<TaaPrimary>"),
    BufferBinding::read_write("colour_out", "array<vec4f>"),
    // Surface vertices of each pixel's path (the vertex after a blend counts α).
    BufferBinding::read_write("path_length", "array<f32>"),
    // Insertion requests: indirect workgroups, count, then (candidate, home, checksum, state).
    BufferBinding::read_write("inserts", "array<atomic<u32>>"),
];

render::gpu_struct! {
    /// The method's parameters (`tc`).
    pub struct TcParams {
        pub rule_kind: u32 => "u32",
        pub relative: u32 => "u32",
        pub param: f32 => "f32",
        pub margin: f32 => "f32",
        pub bias_clamp: f32 => "f32",
        pub survival: f32 => "f32",
        pub samples_per_vertex: u32 => "u32",
        pub max_vertices: f32 => "f32",
        pub store_probability: f32 => "f32",
        /// Pixels: propagation candidates follow the pixels' in the candidate list.
        pub pixels: u32 => "u32",
        /// XOR of the candidate indices this frame: the lowest permuted index wins a record.
        pub candidate_mask: u32 => "u32",
        /// A propagation sample whose hit has no filled record: 0 its estimate is left out of
        /// filled records (`Incomplete::LeaveOut`), 1 it goes on by path tracing (`PathTrace`),
        /// 2 the estimate counts with the empty record read as 0 (`Include`).
        pub incomplete: u32 => "u32",
        /// 1: the tracer offers its primary vertices to the records (one tracer per cache); 0:
        /// it draws the same random numbers but writes nothing (a second rule on a shared
        /// cache, whose offers would repeat the first's).
        pub offers: u32 => "u32",
    }
}

render::gpu_struct! {
    /// A record's moments (luminance for the second and marginal moments), or one stored
    /// vertex's estimates of this frame (`vertices` = 1 valid, 0 none).
    #[derive(Default, PartialEq)]
    pub struct TcRecord {
        /// E[Y] (rgb): the cache value.
        pub mean: [f32; 3] => "vec3f",
        pub vertices: f32 => "f32",
        /// E[Y²].
        pub second: f32 => "f32",
        /// E[E[Y|y]²] (U-statistic over pairs).
        pub marginal: f32 => "f32",
        /// E[(f cos / p)² B²] at the segment's hit.
        pub deferred_bias2: f32 => "f32",
        /// E[B²]: the second moment of the segment's part after next-event estimation (the
        /// BSDF sample's hit), the part Russian roulette keeps with probability q.
        pub continuation2: f32 => "f32",
        /// Mean over vertices of the squared luminance of the vertex mean (a vertex estimate:
        /// its own squared luminance).
        pub mean_sq: f32 => "f32",
        /// Σ wᵢ² of the running mean's weights (moments.rs): with `mean_sq`, Var(mean).
        pub weight2: f32 => "f32",
        /// A vertex estimate: 1 if every sample's hit had a filled record (else it may only
        /// start an empty record).
        pub complete: f32 => "f32",
        pub pad: f32 => "f32",
    }
}

render::gpu_struct! {
    /// A stored vertex: the ray that hits it (propagation re-traces it for the surface).
    #[derive(Default, PartialEq)]
    pub struct TcVertex {
        pub origin: [f32; 3] => "vec3f",
        pub pad0: f32 => "f32",
        pub dir: [f32; 3] => "vec3f",
        pub pad1: f32 => "f32",
    }
}

const _: () = assert!(
    size_of::<TcParams>() == 52 && size_of::<TcRecord>() == 48 && size_of::<TcVertex>() == 32
);
const _: () = assert!(BYTES_PER_RECORD == 16 + 48 + 4 * 48 + 4 * 32 + 4 * 32 + 4 * 16);

/// Counters of one frame (counted on the GPU).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct TerminationStats {
    /// Surface vertices of the tracer's paths, all pixels, in 1/256 vertex (the vertex after a
    /// blend counts α).
    pub path_vertices: u32,
    pub trace_rays: u32,
    pub propagate_rays: u32,
    /// New keys given a slot, and insertion requests refused (a full probe window). Counted by
    /// the insertion after the image: 0 in [`TerminationCache::trace`]'s output, counted in
    /// [`TerminationCache::render`]'s and [`TerminationCache::read_counters`] after the store.
    pub inserted: u32,
    pub insert_failures: u32,
    /// Vertices `tc_store` kept. It runs after the image ([`TerminationCache::store`]): 0 in
    /// [`TerminationCache::trace`]'s output, counted in [`TerminationCache::render`]'s.
    pub stored: u32,
    /// Decisions at a vertex whose record was absent or empty (the path continued).
    pub unknown: u32,
    /// Stored vertices propagated whose samples all read a filled record.
    pub propagated: u32,
    /// Stored vertices propagated with a sample that read no filled record (they only start
    /// empty records).
    pub incomplete: u32,
    /// Records holding moments after this frame's fold.
    pub filled: u32,
}

/// Means over the filled records (luminance) of the statistics the rules read: how fast the
/// cache follows a change in the scene, and why termination moves meanwhile.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct CacheStatistics {
    /// E[Y]: the cache value.
    pub mean: f64,
    /// E[Y²] − E[E[Y|y]²]: average variance of one more segment.
    pub variance: f64,
    /// E[E[Y|y]²] − E[Y]²: average squared bias of terminating into the record.
    pub bias2: f64,
    /// Quantiles over the filled records of their variance (10%, 50%, 90%): where an absolute
    /// threshold lies against the scene's local variances.
    pub variance_quantiles: [f64; 3],
    /// Quantiles over the filled records of their value E[Y] (10%, 50%, 90%).
    pub mean_quantiles: [f64; 3],
}

impl CacheStatistics {
    /// Over the records holding moments; zeros for an empty cache.
    pub fn of(records: &[TcRecord]) -> Self {
        let filled: Vec<RecordMoments> = records
            .iter()
            .filter(|r| r.vertices > 0.0)
            .map(|r| RecordMoments {
                vertices: r.vertices as f64,
                mean: luminance(Vec3::from(r.mean)) as f64,
                second: r.second as f64,
                marginal: r.marginal as f64,
                mean_sq: r.mean_sq as f64,
                weight2: r.weight2 as f64,
            })
            .collect();
        let n = filled.len().max(1) as f64;
        let quantiles = |value: fn(&RecordMoments) -> f64| {
            let mut v: Vec<f64> = filled.iter().map(value).collect();
            v.sort_by(f64::total_cmp);
            [0.1, 0.5, 0.9].map(|q| v.get((q * v.len() as f64) as usize).copied().unwrap_or(0.0))
        };
        Self {
            mean: filled.iter().map(|m| m.mean).sum::<f64>() / n,
            variance: filled.iter().map(|m| m.average_variance()).sum::<f64>() / n,
            bias2: filled.iter().map(|m| m.squared_bias()).sum::<f64>() / n,
            variance_quantiles: quantiles(RecordMoments::average_variance),
            mean_quantiles: quantiles(|m| m.mean),
        }
    }
}

#[derive(Clone, Debug, Default)]
pub struct TerminationOutput {
    pub radiance: Vec<[f32; 4]>,
    pub motion: Vec<[f32; 2]>,
    /// Surface vertices of each pixel's path, the vertex after a blend counting α (the paper's
    /// Fig. 11 image).
    pub path_length: Vec<f32>,
    /// Mean vertices per path.
    pub mean_path_length: f64,
    pub stats: TerminationStats,
    /// The records after this frame's passes.
    pub cache: CacheStatistics,
    pub timings: Vec<PassTiming>,
    pub rays: u64,
    /// One path per pixel plus the propagated vertices.
    pub shaded: u64,
}

/// One rule's tracer over a [`TerminationCache`]: its parameters (`tc`: the rule, survival),
/// its counters and per-pixel outputs, and a bind group with the cache's shared buffers. Rules
/// whose settings have the same [`TerminationSettings::cache_key`] build the same records, so
/// one cache serves them all: its propagation, fold, insertion and store run once a frame, and
/// each rule runs only `tc_trace` ([`TerminationCache::trace_with`]).
pub struct TerminationTracer {
    settings: TerminationSettings,
    /// Whether this tracer's primary vertices are offered to the records (the first tracer of a
    /// cache; the others' offers are the same vertices, see `TcParams::offers`).
    offers: bool,
    tc: wgpu::Buffer,
    /// Only the trace's words (path vertices, trace rays, unknown records) are this tracer's;
    /// the cache's passes count in the cache's own tracer.
    counters: wgpu::Buffer,
    primary: wgpu::Buffer,
    colour: wgpu::Buffer,
    path_length: wgpu::Buffer,
    group: wgpu::BindGroup,
    timer: PassTimer,
}

impl TerminationTracer {
    pub fn settings(&self) -> TerminationSettings {
        self.settings
    }
}

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

    /// The passes' program: the shading library, TAA's primary attributes, the hash cache's
    /// keys and its `hc` parameters (binding 0 of this @group(2), its own module because
    /// hash_key.wgsl imports it from there), this cache's structs and other bindings, the
    /// decision, termination.wgsl.
    pub fn program() -> &'static Program {
        static PROGRAM: std::sync::OnceLock<Program> = std::sync::OnceLock::new();
        PROGRAM.get_or_init(|| {
            let taa_types = taa::types_module();
            let hc_types = hash_cache::types_module();
            let types = Module::generated(
                "package::termination_types",
                &[TcParams::WGSL, TcRecord::WGSL, TcVertex::WGSL],
            );
            let hc = compute::group_module_range(
                "package::hash_cache_bindings",
                2,
                &OWN_GROUP,
                0..1,
                &[&hc_types],
            );
            let bindings = compute::group_module_range(
                "package::termination_bindings",
                2,
                &OWN_GROUP,
                1..OWN_GROUP.len(),
                &[&taa_types, &types],
            );
            PassLibrary::program(
                [
                    taa_types,
                    taa::primary_module(),
                    hc_types,
                    hc,
                    types,
                    bindings,
                    hash_cache::key_module(),
                    decision_module(),
                ],
                [render::wgsl_file!("termination.wgsl")],
            )
        })
    }

    pub fn settings(&self) -> TerminationSettings {
        self.settings
    }

    /// Bytes of the cache (records × bytes per record), as checked against the adapter.
    pub fn cache_bytes(&self) -> u64 {
        self.settings.cache_bytes()
    }

    /// One whole frame: [`Self::update`], [`Self::trace`], [`Self::store`]; the output holds
    /// the four passes' times and the store's count.
    pub fn render(
        &mut self,
        gpu: &Gpu,
        scene: &SceneGpu,
        camera: &Camera,
        seed: u64,
        frame: u32,
    ) -> Result<TerminationOutput, RenderError> {
        let updated = self.update(gpu, scene, camera, seed, frame)?;
        let mut out = self.trace(gpu, scene, updated)?;
        out.timings.extend(self.store(gpu, scene)?);
        let counted = self.read_counters(gpu)?;
        out.stats.stored = counted.stored;
        out.stats.inserted = counted.inserted;
        out.stats.insert_failures = counted.insert_failures;
        Ok(out)
    }

    /// The records the image reads: on the first call the cache is first filled for
    /// `warmup_frames` whole frames (traced by the cache's own tracer), then this frame's
    /// propagation and fold (one submission). Returns their times, for [`Self::trace`].
    pub fn update(
        &mut self,
        gpu: &Gpu,
        scene: &SceneGpu,
        camera: &Camera,
        seed: u64,
        frame: u32,
    ) -> Result<Vec<PassTiming>, RenderError> {
        if self.frames == 0 {
            for k in 0..self.settings.warmup_frames {
                // Warm-up frames draw their own random numbers (frame indices no run reaches).
                let frame = 0x8000_0000 + k;
                self.begin_frame(gpu, scene, camera, seed, frame, WARMUP_MAX_VERTICES);
                self.submit(gpu, scene, &self.update_timer, &TcPass::UPDATE, &self.own.group)?;
                self.submit(gpu, scene, &self.own.timer, &[TcPass::Trace], &self.own.group)?;
                self.store(gpu, scene)?;
            }
        }
        self.begin_frame(gpu, scene, camera, seed, frame, self.settings.max_vertices);
        let timings =
            self.submit(gpu, scene, &self.update_timer, &TcPass::UPDATE, &self.own.group)?;
        if self.derived_unit.is_none() {
            // The scene's radiance scale, from the records the first image reads: fixed for
            // the run, so that a static scene's frames stay independent estimates.
            self.derived_unit = Some(CacheStatistics::of(&self.read_records(gpu)?).mean);
        }
        Ok(timings)
    }

    /// The radiance unit of an absolute threshold for `settings` (`radiance_scale`): the
    /// stated one, or the cache's mean once derived (before that, during the warm-up, 1).
    pub fn radiance_unit(&self, settings: &TerminationSettings) -> f64 {
        match settings.radiance_scale {
            RadianceScale::Stated => settings.radiance_unit,
            RadianceScale::CacheMean => self.derived_unit.unwrap_or(1.0),
        }
    }

    /// The frame's image by the cache's own tracer (its settings' rule): [`Self::trace_with`].
    pub fn trace(
        &self,
        gpu: &Gpu,
        scene: &SceneGpu,
        updated: Vec<PassTiming>,
    ) -> Result<TerminationOutput, RenderError> {
        self.trace_with(gpu, scene, &self.own, updated)
    }

    /// The frame's image by `tracer` after [`Self::update`] (`updated`: times reported first,
    /// empty for a tracer that does not report the cache's passes): the tracer with its rule's
    /// decision over the folded records, and the frame's read-back. Its output is what the
    /// tracer's rule gives alone: its image and trace counters with the cache's counts
    /// (propagated vertices and rays, records).
    pub fn trace_with(
        &self,
        gpu: &Gpu,
        scene: &SceneGpu,
        tracer: &TerminationTracer,
        updated: Vec<PassTiming>,
    ) -> Result<TerminationOutput, RenderError> {
        let absolute = matches!(
            tracer.settings.rule,
            TerminationRule::VarianceBounding { relative: false, .. }
        );
        if absolute && tracer.settings.radiance_scale == RadianceScale::CacheMean {
            let unit = self.radiance_unit(&tracer.settings);
            if !(unit > 0.0 && unit.is_finite()) {
                return Err(RenderError::Settings(format!(
                    "Termination radiance_scale CacheMean: the cache's mean radiance is {unit} after {} warm-up frames (no filled record to derive the unit from); use more warmup_frames or radiance_scale: Stated",
                    self.settings.warmup_frames
                )));
            }
        }
        // The frame's parameters with the tracer's rule; its trace counters cleared (the
        // cache's words of the own tracer's counters are the frame's so far).
        let tc = self.params(&tracer.settings, self.frame_params, tracer.offers);
        gpu.queue.write_buffer(&tracer.tc, 0, bytemuck::bytes_of(&tc));
        for word in TRACE_COUNTERS {
            gpu.queue.write_buffer(&tracer.counters, word * 4, &[0u8; 4]);
        }
        let mut timings = updated;
        timings.extend(self.submit(gpu, scene, &tracer.timer, &[TcPass::Trace], &tracer.group)?);
        let [colour, primary, path_length, traced, counters] = copy_all(
            gpu,
            [
                (&tracer.colour, "termination colour"),
                (&tracer.primary, "termination primary hits"),
                (&tracer.path_length, "termination path length"),
                (&tracer.counters, "termination trace counters"),
                (&self.own.counters, "termination counters"),
            ],
        );
        let radiance = colour.read(gpu)?;
        let primary: Vec<TaaPrimary> = primary.read(gpu)?;
        let path_length: Vec<f32> = path_length.read(gpu)?;
        let mut words: Vec<u32> = counters.read(gpu)?;
        let traced: Vec<u32> = traced.read(gpu)?;
        for word in TRACE_COUNTERS {
            words[word as usize] = traced[word as usize];
        }
        let stats = stats_of(&words);
        let pixels = self.width as u64 * self.height as u64;
        Ok(TerminationOutput {
            radiance,
            motion: primary.iter().map(|p| p.motion).collect(),
            path_length,
            mean_path_length: stats.path_vertices as f64 / 256.0 / pixels as f64,
            stats,
            cache: CacheStatistics::of(&self.read_records(gpu)?),
            timings,
            rays: stats.trace_rays as u64 + stats.propagate_rays as u64,
            shaded: pixels + stats.propagated as u64 + stats.incomplete as u64,
        })
    }

    /// After the frame's image: the frame's new keys get slots and the winning candidates become
    /// stored vertices, which the next frame propagates. Reads only the cache's own buffers and
    /// parameters (no ray), so other methods' work since [`Self::trace`] changes nothing. Ends
    /// the frame.
    pub fn store(&mut self, gpu: &Gpu, scene: &SceneGpu) -> Result<Vec<PassTiming>, RenderError> {
        let timings =
            self.submit(gpu, scene, &self.store_timer, &TcPass::STORE, &self.own.group)?;
        self.frames += 1;
        Ok(timings)
    }

    /// The parameters of a pass with `settings`' rule in the frame of `frame` (its candidate
    /// mask and record memory).
    fn params(&self, settings: &TerminationSettings, frame: TcParams, offers: bool) -> TcParams {
        let (rule_kind, relative, param, margin, bias_clamp) = rule_words(&settings.rule);
        let param = match settings.rule {
            TerminationRule::VarianceBounding { t, relative: false } => {
                let unit = self.radiance_unit(settings);
                (t * unit * unit) as f32
            }
            _ => param,
        };
        TcParams {
            rule_kind,
            relative,
            param,
            margin,
            bias_clamp,
            survival: settings.survival as f32,
            offers: offers as u32,
            ..frame
        }
    }

    /// Writes the frame's parameters (the cache's frame, `hc`, the own tracer's `tc`) and
    /// clears the counters.
    fn begin_frame(
        &mut self,
        gpu: &Gpu,
        scene: &SceneGpu,
        camera: &Camera,
        seed: u64,
        frame: u32,
        max_vertices: u32,
    ) {
        let s = &self.settings;
        // The hash cache's keys round the voxel down to a power of two (sub-pixel voxels, the
        // paper's HashCache); twice the scale keeps this cache's rounding up (voxels of at least
        // lod_scale footprints), as it was tuned.
        let keys = HashCacheSettings {
            capacity: s.capacity,
            probe_limit: s.probe_limit,
            lod_scale: 2.0 * s.lod_scale,
            jitter: s.jitter,
            ..Default::default()
        }
        .key_params(camera, self.height);
        let hc = HashCacheParams {
            capacity: s.capacity,
            probe_limit: s.probe_limit,
            frame: 0,
            max_age: 0,
            pixel_angle: keys.pixel_angle,
            lod_scale: keys.lod_scale,
            normal_lod: keys.normal_lod as u32,
            jitter: keys.jitter as u32,
            lookup: 0,
            max_samples: 0.0,
            voxel_jitter_seed: 0,
            pad: 0,
            primary_jitter: [0.0; 2],
            pad2: [0.0; 2],
        };
        let frame_params = TcParams {
            samples_per_vertex: s.samples_per_vertex,
            max_vertices: max_vertices.min(s.max_vertices) as f32,
            store_probability: s.store_probability as f32,
            pixels: self.width * self.height,
            candidate_mask: scene::mix64(seed ^ ((frame as u64) << 32)) as u32 & 0x0fff_ffff,
            incomplete: match s.incomplete {
                Incomplete::LeaveOut => 0,
                Incomplete::PathTrace => 1,
                Incomplete::Include => 2,
            },
            ..bytemuck::Zeroable::zeroed()
        };
        self.frame_params = frame_params;
        let tc = self.params(&self.settings, frame_params, self.own.offers);
        self.frame.prepare(gpu, scene, 1, 0, seed, frame);
        gpu.queue.write_buffer(&self.hc, 0, bytemuck::bytes_of(&hc));
        gpu.queue.write_buffer(&self.own.tc, 0, bytemuck::bytes_of(&tc));
        gpu.queue.write_buffer(&self.own.counters, 0, &[0u8; COUNTERS as usize * 4]);
        gpu.queue.write_buffer(&self.inserts, 0, bytemuck::cast_slice(&INSERT_HEADER));
    }

    /// `passes` in order as one submission timed by `timer` (whose names are theirs), bound
    /// with `group` (the own tracer's, or another tracer's for its trace).
    fn submit(
        &self,
        gpu: &Gpu,
        scene: &SceneGpu,
        timer: &PassTimer,
        passes: &[TcPass],
        group: &wgpu::BindGroup,
    ) -> Result<Vec<PassTiming>, RenderError> {
        let mut timed = timer.begin(gpu, "termination");
        for (index, &p) in passes.iter().enumerate() {
            debug_assert_eq!(timer.names()[index], p.name());
            if p == TcPass::Insert {
                timed.encoder().copy_buffer_to_buffer(&self.inserts, 0, &self.insert_args, 0, 12);
                timed.pass(index, |pass| {
                    self.frame.bind(gpu, scene, pass);
                    pass.set_bind_group(2, group, &[]);
                    let [claim, win, settle] = [4, 5, 6].map(|e| self.pipelines[e].get());
                    for _ in 0..INSERT_ROUNDS.min(self.settings.probe_limit) {
                        pass.set_pipeline(&claim);
                        pass.dispatch_workgroups_indirect(&self.insert_args, 0);
                        pass.set_pipeline(&win);
                        pass.dispatch_workgroups_indirect(&self.insert_args, 0);
                    }
                    pass.set_pipeline(&settle);
                    pass.dispatch_workgroups_indirect(&self.insert_args, 0);
                })?;
                continue;
            }
            let entry = match p {
                TcPass::Propagate => 0,
                TcPass::Fold => 1,
                TcPass::Trace => 2,
                TcPass::Insert | TcPass::Store => 3,
            };
            let pipeline = &self.pipelines[entry];
            let [x, y, z] = self.workgroups(p);
            timed.pass(index, |pass| {
                pass.set_pipeline(&pipeline.get());
                self.frame.bind(gpu, scene, pass);
                pass.set_bind_group(2, group, &[]);
                pass.dispatch_workgroups(x, y, z);
            })?;
        }
        timed.submit()
    }

    /// Workgroups of `pass`: per stored vertex, per record, or per 8x8 pixels.
    fn workgroups(&self, pass: TcPass) -> [u32; 3] {
        let records = self.settings.capacity;
        match pass {
            TcPass::Propagate => [(records * VERTICES_PER_RECORD as u32).div_ceil(64), 1, 1],
            TcPass::Fold | TcPass::Store => [records.div_ceil(64), 1, 1],
            // Dispatched indirectly over the frame's requests (`inserts`).
            TcPass::Insert => [0, 1, 1],
            TcPass::Trace => [self.width.div_ceil(8), self.height.div_ceil(8), 1],
        }
    }

    /// The frame's counters so far (after [`Self::store`]: the insertions' and the store's too).
    pub fn read_counters(&self, gpu: &Gpu) -> Result<TerminationStats, RenderError> {
        Ok(stats_of(&read_pod::<u32>(gpu, &self.own.counters, "termination counters")?))
    }
}

/// The counters' words as statistics.
fn stats_of(c: &[u32]) -> TerminationStats {
    TerminationStats {
        path_vertices: c[0],
        trace_rays: c[1],
        propagate_rays: c[2],
        inserted: c[3],
        insert_failures: c[4],
        stored: c[5],
        unknown: c[6],
        propagated: c[7],
        incomplete: c[8],
        filled: c[9],
    }
}

/// The cache's buffers every tracer binds.
#[derive(Clone, Copy)]
struct SharedBuffers<'a> {
    hc: &'a wgpu::Buffer,
    slots: &'a wgpu::Buffer,
    records: &'a wgpu::Buffer,
    vertices: &'a wgpu::Buffer,
    inserts: &'a wgpu::Buffer,
}

/// A tracer's own buffers (sizes checked by [`TerminationCache::new`]) and its bind group.
fn build_tracer(
    gpu: &Gpu,
    layout: &wgpu::BindGroupLayout,
    shared: SharedBuffers,
    settings: TerminationSettings,
    offers: bool,
    pixels: u64,
) -> TerminationTracer {
    let buffer = |label: &str, size: u64, usage: wgpu::BufferUsages| {
        gpu.device.create_buffer(&wgpu::BufferDescriptor {
            label: Some(label),
            size,
            usage,
            mapped_at_creation: false,
        })
    };
    let rw =
        wgpu::BufferUsages::STORAGE | wgpu::BufferUsages::COPY_SRC | wgpu::BufferUsages::COPY_DST;
    let tc = buffer(
        "termination tc",
        size_of::<TcParams>() as u64,
        wgpu::BufferUsages::STORAGE | wgpu::BufferUsages::COPY_DST,
    );
    let counters = buffer("termination counters", COUNTERS * 4, rw);
    let primary = buffer("termination primary", pixels * size_of::<TaaPrimary>() as u64, rw);
    let colour = buffer("termination colour", pixels * 16, rw);
    let path_length = buffer("termination path length", pixels * 4, rw);
    let group = render::compute::buffer_group(
        gpu,
        "termination",
        layout,
        &[
            shared.hc,
            &tc,
            shared.slots,
            shared.records,
            shared.vertices,
            &counters,
            &primary,
            &colour,
            &path_length,
            shared.inserts,
        ],
    );
    TerminationTracer {
        settings,
        offers,
        tc,
        counters,
        primary,
        colour,
        path_length,
        group,
        timer: PassTimer::new(gpu, &[TC_TRACE_PASS]),
    }
}

impl TerminationCache {
    /// Each record's moments (slot order), for tests.
    pub fn read_records(&self, gpu: &Gpu) -> Result<Vec<TcRecord>, RenderError> {
        let all: Vec<TcRecord> = read_pod(gpu, &self.records, "termination records")?;
        Ok(all[..self.settings.capacity as usize].to_vec())
    }

    /// Slot words (checksum, claim, stored vertices, insertion claim), for tests.
    pub fn read_slots(&self, gpu: &Gpu) -> Result<Vec<[u32; 4]>, RenderError> {
        read_pod(gpu, &self.slots, "termination slots")
    }
}
