//! The cache's GPU state: its buffers, two caches reprojected into each other, pipelines and
//! bind groups.

mod resolve;
mod stage;
mod state;

use crate::gpu_types::{HEADER_WORDS, PIXEL_ATOMICS, SscParams};
use crate::passes::{DISPATCHES, PASSES, STAGE_DISPATCHES};
use crate::program::{OWN_GROUP, program};
use crate::settings::SampleCacheSettings;
use render::error::RenderError;
use render::frame_bindings::FrameBindings;
use render::gpu::Gpu;
use render::pass_library::LibraryPipeline;
use render::readback::Staging;
use render::scene_gpu::SceneGpu;
use render::timing::{PassTimer, PassTiming};

struct Cache {
    mask: wgpu::Buffer,
    slots: wgpu::Buffer,
}

pub struct SampleCache {
    settings: SampleCacheSettings,
    width: u32,
    height: u32,
    layout: wgpu::BindGroupLayout,
    pipelines: Pipelines,
    params: wgpu::Buffer,
    caches: [Cache; 2],
    pixel_atomics: wgpu::Buffer,
    reserve_keys: wgpu::Buffer,
    work: wgpu::Buffer,
    /// Indirect arguments of the retrace list (bytes 0-11) and the shade list (12-23), copied
    /// from `work`'s header (a buffer bound as storage cannot be a dispatch's indirect buffer).
    list_args: wgpu::Buffer,
    /// Whether the list passes are dispatched indirectly (the default) or over N · pixels.
    indirect: bool,
    out: wgpu::Buffer,
    /// The image and its primary attributes for a TAA resolve ([`Self::taa_inputs`]).
    colour: wgpu::Buffer,
    primary: wgpu::Buffer,
    out_readback: Staging,
    header_readback: Staging,
    frame: FrameBindings,
    bind_groups: [wgpu::BindGroup; 2],
    /// Index of the cache holding the last frame (the source of the next reprojection).
    current: usize,
    /// One timer per stage of [`PASSES`] (each stage is its own submission).
    timers: Vec<PassTimer>,
    frames: u32,
    /// The frame under way: its seed and number, and the dispatch times of its stages so far.
    pending: Option<(u64, u32, Vec<PassTiming>)>,
}

struct Pipelines {
    begin: LibraryPipeline,
    reserve: LibraryPipeline,
    gather: LibraryPipeline,
    closest: LibraryPipeline,
    retrace: LibraryPipeline,
    retrace_args: LibraryPipeline,
    retrace_list: LibraryPipeline,
    finish: LibraryPipeline,
    rates: LibraryPipeline,
    select: LibraryPipeline,
    shade_args: LibraryPipeline,
    shade: LibraryPipeline,
    reconstruct: LibraryPipeline,
    audit: LibraryPipeline,
}

impl SampleCache {
    pub fn new(
        gpu: &Gpu,
        scene: &SceneGpu,
        settings: SampleCacheSettings,
    ) -> Result<Self, RenderError> {
        settings.validate().map_err(|e| RenderError::Settings(format!("sample cache: {e}")))?;
        let (width, height) = (scene.settings().width, scene.settings().height);
        let n = settings.slots as u64;
        // The adapter's limit is per binding: check the largest per-pixel buffer (one cache's
        // slots) here; `buffer` below checks every buffer on its own.
        gpu.check_resolution(width, height, 32 * n)?;
        // No var<workgroup> anywhere in the cache passes.
        for pass in PASSES {
            gpu.check_workgroup_memory(pass, 0)?;
        }
        let pixels = width as u64 * height as u64;
        let device = &gpu.device;
        let buffer = |label: &str,
                      size: u64,
                      usage: wgpu::BufferUsages|
         -> Result<wgpu::Buffer, RenderError> {
            gpu.check_buffer_size(label, size)?;
            Ok(device.create_buffer(&wgpu::BufferDescriptor {
                label: Some(label),
                size,
                usage,
                mapped_at_creation: false,
            }))
        };
        let rw = wgpu::BufferUsages::STORAGE
            | wgpu::BufferUsages::COPY_SRC
            | wgpu::BufferUsages::COPY_DST;
        let caches = [
            Cache {
                mask: buffer("ssc mask a", pixels * 4, rw)?,
                slots: buffer("ssc slots a", pixels * n * 32, rw)?,
            },
            Cache {
                mask: buffer("ssc mask b", pixels * 4, rw)?,
                slots: buffer("ssc slots b", pixels * n * 32, rw)?,
            },
        ];
        let pixel_atomics = buffer("ssc pixel atomics", pixels * 4 * PIXEL_ATOMICS, rw)?;
        // A reservation key holds a sample's index (slot × pixels + pixel) in 30 bits.
        if n * pixels > 1 << 30 {
            return Err(RenderError::Settings(format!(
                "sample cache: {n} slots x {pixels} pixels is over the 2^30 samples a reservation key indexes"
            )));
        }
        let reserve_keys = buffer("ssc reservation keys", pixels * n * 4, rw)?;
        let work = buffer("ssc work", (HEADER_WORDS + pixels * n) * 4, rw)?;
        let list_args = buffer(
            "ssc list dispatch",
            24,
            wgpu::BufferUsages::INDIRECT | wgpu::BufferUsages::COPY_DST,
        )?;
        let out = buffer("ssc out", pixels * 32, rw)?;
        let colour = buffer("ssc colour", pixels * 16, rw)?;
        let primary = buffer("ssc primary", pixels * size_of::<taa::TaaPrimary>() as u64, rw)?;
        let out_readback = Staging::new(gpu, "sample cache output", out.size());
        let header_readback = Staging::new(gpu, "sample cache counters", HEADER_WORDS * 4);
        let params = buffer(
            "ssc params",
            size_of::<SscParams>() as u64,
            wgpu::BufferUsages::STORAGE | wgpu::BufferUsages::COPY_DST,
        )?;

        let (
            layout,
            [
                begin,
                reserve,
                gather,
                closest,
                retrace,
                retrace_args,
                retrace_list,
                finish,
                rates,
                select,
                shade_args,
                shade,
                reconstruct,
                audit,
            ],
        ) = scene.library_pass(
            gpu,
            "shaders/sample_cache/*.wgsl",
            program(),
            &OWN_GROUP,
            [
                "begin_main",
                "reserve_main",
                "gather_main",
                "closest_main",
                "retrace_main",
                "retrace_args_main",
                "retrace_list_main",
                "finish_main",
                "rates_main",
                "select_main",
                "shade_args_main",
                "shade_main",
                "reconstruct_main",
                "audit_main",
            ],
        )?;
        let pipelines = Pipelines {
            begin,
            reserve,
            gather,
            closest,
            retrace,
            retrace_args,
            retrace_list,
            finish,
            rates,
            select,
            shade_args,
            shade,
            reconstruct,
            audit,
        };
        let make = |src: &Cache, dst: &Cache| {
            render::compute::buffer_group(
                gpu,
                "sample cache",
                &layout,
                &[
                    &params,
                    &src.mask,
                    &src.slots,
                    &pixel_atomics,
                    &dst.slots,
                    &dst.mask,
                    &work,
                    &out,
                    &colour,
                    &primary,
                    &reserve_keys,
                ],
            )
        };
        // bind_groups[i]: reproject cache i into cache 1 - i.
        let bind_groups = [make(&caches[0], &caches[1]), make(&caches[1], &caches[0])];
        Ok(Self {
            settings,
            width,
            height,
            layout,
            pipelines,
            params,
            caches,
            pixel_atomics,
            reserve_keys,
            work,
            list_args,
            indirect: true,
            out,
            colour,
            primary,
            out_readback,
            header_readback,
            frame: FrameBindings::new(gpu, scene),
            bind_groups,
            current: 0,
            timers: STAGE_DISPATCHES
                .iter()
                .map(|r| PassTimer::new(gpu, &DISPATCHES[r.clone()]))
                .collect(),
            frames: 0,
            pending: None,
        })
    }

    pub fn settings(&self) -> &SampleCacheSettings {
        &self.settings
    }

    /// Dispatch the list passes indirectly (default: one thread per entry) or directly over N ·
    /// pixels threads (the former way; for comparisons and benchmarks). Same results either way.
    pub fn set_indirect(&mut self, indirect: bool) {
        self.indirect = indirect;
    }

    pub fn layout(&self) -> &wgpu::BindGroupLayout {
        &self.layout
    }
}
