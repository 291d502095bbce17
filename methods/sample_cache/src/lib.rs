//! Stable sample cache (Philippi, Jensen & Frisvad 2025, "Stable Sample Caching for Interactive
//! Stereoscopic Ray Tracing", sections 3.1-3.5): a screen-space cache of N first-hit samples per
//! pixel, carried from frame to frame by forward reprojection, retraced sparsely, shaded
//! sparsely, and averaged into the image. See README.md in this folder for the map, and
//! docs/methods/sample-cache.md for the choices.
//!
//! Passes per frame (shaders/, one compute pass each, timed):
//! `reserve` (reproject.wgsl: begin_main, reserve_main, gather_main, closest_main), `trace` (retrace.wgsl: retrace_main,
//! list_dispatch.wgsl retrace_args_main, retrace.wgsl retrace_list_main, finish_main),
//! `shade` (shading_rate.wgsl rates_main + select_main, list_dispatch.wgsl shade_args_main,
//! shade.wgsl shade_main), `reconstruct` (reconstruct.wgsl).
//!
//! The two list passes (retrace_list_main, shade_main) are dispatched indirectly: one thread
//! per list entry, the workgroup counts written on the GPU by the args passes and copied into
//! an indirect buffer ([`SampleCache::set_indirect`] turns it off for comparisons: then N ·
//! pixels threads launch and those past the list's end exit).
//!
//! 64-bit atomics: the paper packs (closest depth, slope Δn) into one 64-bit atomicMin during
//! reprojection. WGSL core has only 32-bit atomics, so after the reservation one pass per pixel
//! (`gather_main`) writes the farthest visible depth of the samples the pixel kept, and another
//! (`closest_main`) the closest depth with its slope, both exact from the pixel's own samples; no
//! precision lost to packing; t_max of the 3x3 neighbours still costs one load each.
//!
//! Deterministic: the same scene, seed and settings give the same bits on any adapter. A pixel
//! keeps the N lowest reservation keys that reach it (`reservation.rs`), sorted by a chain of
//! atomics whose result does not depend on the order threads run in; every random number is
//! seeded by (seed, frame, pixel, slot); counters are integer atomics.

pub mod density;
pub mod reservation;
pub mod settings;
pub mod shading_rate;
pub mod slope;
pub mod storage;

pub use settings::{Retrace, SampleCacheSettings, ShadingMode};
pub use storage::{GpuSlot, SscSlot};

use render::compute::BufferBinding;
use render::error::RenderError;
use render::frame_bindings::FrameBindings;
use render::gpu::Gpu;
use render::gpu_struct::GpuStruct;
use render::pass_library::LibraryPipeline;
use render::pass_library::PassLibrary;
use render::readback::{Staging, read_pod};
use render::scene_gpu::SceneGpu;
use render::shader::{Module, Program};
use render::timing::{PassTimer, PassTiming};

/// Pass names in [`CacheFrame::timings`]: the stages of a frame, each one submission
/// ([`SampleCache::stage`]); the frame's systems run them in this order.
pub const PASSES: [&str; 4] = ["reserve", "trace", "shade", "reconstruct"];

/// The dispatches (indices into [`DISPATCHES`]) of each of [`PASSES`].
const STAGE_DISPATCHES: [std::ops::Range<usize>; 4] = [0..4, 4..8, 8..12, 12..13];

/// The dispatches of a frame, `PASS/entry`, in order; each is timed on its own
/// ([`CacheFrame::dispatch_timings`]) and the pass time is the sum of its dispatches'.
pub const DISPATCHES: [&str; 13] = [
    "reserve/begin_main",
    "reserve/reserve_main",
    "reserve/gather_main",
    "reserve/closest_main",
    "trace/retrace_main",
    "trace/retrace_args_main",
    "trace/retrace_list_main",
    "trace/finish_main",
    "shade/rates_main",
    "shade/select_main",
    "shade/shade_args_main",
    "shade/shade_main",
    "reconstruct/reconstruct_main",
];

/// Threads per workgroup of the list passes (`SSC_LIST_WORKGROUP` in storage.wgsl).
pub const LIST_WORKGROUP: u32 = 64;
/// WebGPU's guaranteed minimum of `max_compute_workgroups_per_dimension` (`SSC_MAX_GROUPS_X`).
pub const MAX_GROUPS_X: u32 = 65_535;

/// Workgroups `[x, y, 1]` of a list pass over `count` entries: x · y · LIST_WORKGROUP >= count
/// with x within every adapter's limit. The GPU's twin (list_dispatch.wgsl) writes the indirect
/// arguments; on the CPU this is the direct dispatch's worst case.
pub fn list_dispatch(count: u32) -> [u32; 3] {
    let groups = count.div_ceil(LIST_WORKGROUP);
    let x = groups.min(MAX_GROUPS_X);
    let y = if x > 0 { groups.div_ceil(x) } else { 0 };
    [x, y, 1]
}

/// Header words of the indirect arguments (`SSC_RETRACE_ARGS`, `SSC_SHADE_ARGS`).
const RETRACE_ARGS_WORD: u64 = 35;
const SHADE_ARGS_WORD: u64 = 38;

const HEADER_WORDS: u64 = 48;
/// Words per pixel of `pixel_atomics` (`SSC_ATOMICS`).
const PIXEL_ATOMICS: u64 = 5;
const AUDIT_WORD: u64 = 32;
/// The cache's own @group(2), declared into its WGSL: params, source mask and slots (read),
/// then pixel atomics, destination slots and mask, work lists, output, and the inputs of a TAA
/// resolve over the image (colour, closest visible sample's primary attributes).
const OWN_GROUP: [BufferBinding; 11] = [
    BufferBinding::read("ssc", "SscParams"),
    BufferBinding::read("src_mask", "array<u32>"),
    BufferBinding::read("src_slots", "array<SscSlot>"),
    // SSC_ATOMICS words per pixel: the reserved mask and the farthest visible depth (gather_main),
    // the retrace results (bits 0-15: visible, 16-31: traced), and the closest visible sample's
    // depth and Δn (closest_main).
    BufferBinding::read_write("pixel_atomics", "array<atomic<u32>>"),
    BufferBinding::read_write("dst_slots", "array<SscSlot>"),
    BufferBinding::read_write("dst_mask", "array<u32>"),
    BufferBinding::read_write("ssc_work", "array<atomic<u32>>"),
    BufferBinding::read_write("ssc_out", "array<SscPixel>"),
    // The reconstruction again in the layouts `Taa::resolve_external` copies from.
    BufferBinding::read_write("ssc_colour", "array<vec4f>"),
    BufferBinding::read_write("ssc_primary", "array<TaaPrimary>"),
    // The reservation's keys, N per pixel (layered as the slots): the complement of the
    // lowest keys that reached the pixel, in order (reproject.wgsl).
    BufferBinding::read_write("reserve_keys", "array<atomic<u32>>"),
];

/// The cache passes' program: the shading library, the cache's structs and @group(2), its
/// storage, slope and selection modules, and one entry-point file per stage's passes.
pub fn program() -> &'static Program {
    static PROGRAM: std::sync::OnceLock<Program> = std::sync::OnceLock::new();
    PROGRAM.get_or_init(|| {
        let types = Module::generated(
            "package::sample_cache_types",
            &[SscParams::WGSL, storage::SscSlot::WGSL, SscPixel::WGSL],
        );
        let taa_types = taa::types_module();
        let bindings = render::compute::group_module(
            "package::sample_cache_bindings",
            2,
            &OWN_GROUP,
            &[&types, &taa_types],
        );
        PassLibrary::program(
            [
                types,
                taa_types,
                taa::primary_module(),
                bindings,
                render::wgsl_file!("storage.wgsl"),
                render::wgsl_file!("slope.wgsl"),
                render::wgsl_file!("selection.wgsl"),
            ],
            [
                render::wgsl_file!("reproject.wgsl"),
                render::wgsl_file!("retrace.wgsl"),
                render::wgsl_file!("shading_rate.wgsl"),
                render::wgsl_file!("shade.wgsl"),
                render::wgsl_file!("list_dispatch.wgsl"),
                render::wgsl_file!("reconstruct.wgsl"),
            ],
        )
    })
}

render::gpu_struct! {
    /// The cache's parameters (`ssc`, @group(2) binding 0).
    pub struct SscParams {
        pub width: u32 => "u32",
        pub height: u32 => "u32",
        /// N, slots per pixel.
        pub slots: u32 => "u32",
        pub frame: u32 => "u32",
        /// 0 single, 1 multi, 2 adaptive.
        pub retrace: u32 => "u32",
        /// 0 uniform, 1 adaptive.
        pub shading: u32 => "u32",
        /// Side of the base-rate block, pixels.
        pub base_block: u32 => "u32",
        /// M, buckets of the importance histogram.
        pub buckets: u32 => "u32",
        pub n_target: f32 => "f32",
        pub delta: f32 => "f32",
        pub epsilon0: f32 => "f32",
        pub epsilon1: f32 => "f32",
        /// Minimum blend weight.
        pub alpha: f32 => "f32",
        /// Dynamic shading budget, samples.
        pub shading_budget: f32 => "f32",
        /// φ, the angle of a pixel's diagonal.
        pub pixel_diagonal_angle: f32 => "f32",
        /// 1: App. C's α_min from the material's roughness instead of `alpha`.
        pub roughness_alpha: u32 => "u32",
    }
}

render::gpu_struct! {
    /// Per output pixel: reconstructed radiance, motion (pixels, now -> previous frame), trace
    /// flags and rays traced.
    #[derive(Default)]
    pub struct SscPixel {
        pub radiance: [f32; 4] => "vec4f",
        pub motion: [f32; 2] => "vec2f",
        /// Bit 0: base-rate pixel, bit 1: flagged by the slope test, bit 2: hole.
        pub flags: u32 => "u32",
        pub rays: u32 => "u32",
    }
}

/// The former name of [`SscPixel`].
pub type GpuPixel = SscPixel;

pub const FLAG_BASE: u32 = 1;
pub const FLAG_SLOPE: u32 = 2;
pub const FLAG_HOLE: u32 = 4;

/// Counters of one frame (exact integers from the GPU's atomics).
#[derive(Clone, Debug, Default, PartialEq)]
pub struct CacheStats {
    pub shaded: u32,
    /// Primary-visibility rays: retraces and new samples (the rays of the paper's figure 7).
    pub rays: u32,
    /// Every ray of the frame: `rays` + the shadow and bounce rays of the shaded paths.
    pub all_rays: u32,
    pub new_samples: u32,
    pub purged: u32,
    pub reprojected: u32,
    pub dropped: u32,
    pub visible: u32,
    pub occupied: u32,
    /// Adaptive shading's samples shaded outside the importance budget: the base rate's, and
    /// the first of each pixel with no shaded visible sample.
    pub base_shaded: u32,
    pub slope_flagged: u32,
    /// Entries of the retrace list.
    pub retrace_listed: u32,
    /// The workgroups the GPU computed for the retrace and shade lists (indirect arguments).
    pub list_args: [[u32; 3]; 2],
    /// Importance bounds (w_min, w_max) of this frame's histogram buckets (last frame's).
    pub importance_bounds: (f32, f32),
    /// Histogram of the frame (adaptive shading), and the threshold bucket and coin chosen.
    pub histogram: Vec<u32>,
    pub threshold: u32,
    pub coin: f32,
}

/// One frame of the cache.
#[derive(Clone, Debug, Default)]
pub struct CacheFrame {
    pub radiance: Vec<[f32; 4]>,
    pub motion: Vec<[f32; 2]>,
    pub flags: Vec<u32>,
    pub stats: CacheStats,
    /// Per pass of [`PASSES`]: the sum of its dispatches.
    pub timings: Vec<PassTiming>,
    /// Per dispatch of [`DISPATCHES`].
    pub dispatch_timings: Vec<PassTiming>,
}

/// The whole cache as the last frame left it (tests, debugging).
#[derive(Clone, Debug)]
pub struct CacheState {
    pub masks: Vec<u32>,
    /// `slots * pixels`, layered: slot s of pixel p at `s * pixels + p`.
    pub slots: Vec<GpuSlot>,
}

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

    /// Renders one frame: call after `scene.update` for this frame's scene. `frame` seeds the
    /// frame's randomness (with `seed`) and drives the round robins. The four stages of
    /// [`PASSES`] in order; the frame's systems call [`Self::stage`] one by one instead.
    pub fn render(
        &mut self,
        gpu: &Gpu,
        scene: &SceneGpu,
        seed: u64,
        frame: u32,
    ) -> Result<CacheFrame, RenderError> {
        self.begin_frame(seed, frame);
        for stage in 0..PASSES.len() {
            self.stage(gpu, scene, stage)?;
        }
        self.finish_frame(gpu)
    }

    /// Starts frame `frame`; then [`Self::stage`] 0 to 3, then [`Self::finish_frame`].
    pub fn begin_frame(&mut self, seed: u64, frame: u32) {
        self.pending = Some((seed, frame, Vec::new()));
    }

    /// Stage `stage` of [`PASSES`] (reserve = reprojection, trace, shade, reconstruct) as one
    /// timed submission. Each stage writes the cache's own frame parameters from the scene as
    /// it is then.
    pub fn stage(&mut self, gpu: &Gpu, scene: &SceneGpu, stage: usize) -> Result<(), RenderError> {
        let (w, h) = (self.width, self.height);
        if scene.settings().width != w || scene.settings().height != h {
            return Err(RenderError::Settings(format!(
                "sample cache is {w}x{h}, the scene {}x{}",
                scene.settings().width,
                scene.settings().height
            )));
        }
        let Some((seed, frame, _)) = self.pending else {
            return Err(RenderError::Settings("sample cache: stage before begin_frame".into()));
        };
        self.frame.prepare(gpu, scene, 1, 0, seed, frame);
        let s = &self.settings;
        if stage == 0 {
            let vfov = 2.0 * tan_half_fov(scene).atan();
            let pixels = w * h;
            let params = SscParams {
                width: w,
                height: h,
                slots: s.slots,
                frame,
                retrace: match s.retrace {
                    Retrace::Single => 0,
                    Retrace::Multi => 1,
                    Retrace::Adaptive => 2,
                },
                shading: match s.shading {
                    ShadingMode::Uniform => 0,
                    ShadingMode::Adaptive => 1,
                },
                base_block: s.base_block,
                buckets: s.buckets,
                n_target: s.n_target,
                delta: s.delta,
                epsilon0: s.epsilon0,
                epsilon1: s.epsilon1,
                alpha: s.alpha,
                shading_budget: s.shading_rate * pixels as f32,
                pixel_diagonal_angle: slope::pixel_diagonal_angle(vfov, h),
                roughness_alpha: s.roughness_alpha as u32,
            };
            gpu.queue.write_buffer(&self.params, 0, bytemuck::bytes_of(&params));
        }

        let mut timed = self.timers[stage].begin(gpu, PASSES[stage]);
        if stage == 0 {
            let encoder = timed.encoder();
            encoder.clear_buffer(&self.pixel_atomics, 0, None);
            encoder.clear_buffer(&self.reserve_keys, 0, None);
            // Header words 0-5 and 10-31; 6-9 (importance bounds) carry over, begin_main moves them.
            encoder.clear_buffer(&self.work, 0, Some(24));
            encoder.clear_buffer(&self.work, 40, Some((HEADER_WORDS - 10) * 4));
            if self.frames == 0 {
                // The very first frame reprojects an empty cache.
                encoder.clear_buffer(&self.caches[self.current].mask, 0, None);
                encoder.clear_buffer(&self.work, 0, Some(HEADER_WORDS * 4));
            }
        }
        let bind_group = &self.bind_groups[self.current];
        let (gx, gy) = (w.div_ceil(8), h.div_ceil(8));
        let p = &self.pipelines;
        // A list pass: its indirect arguments' offset in `list_args` and header word in `work`.
        let list = |l: u64| Some((12 * l, [RETRACE_ARGS_WORD, SHADE_ARGS_WORD][l as usize]));
        let whole_list = list_dispatch(s.slots * w * h);
        // In the order of DISPATCHES: pipeline, direct workgroups, list.
        let dispatches: [(&LibraryPipeline, [u32; 3], Option<(u64, u64)>); 13] = [
            (&p.begin, [1, 1, 1], None),
            (&p.reserve, [gx, gy, s.slots], None),
            (&p.gather, [gx, gy, 1], None),
            (&p.closest, [gx, gy, 1], None),
            (&p.retrace, [gx, gy, 1], None),
            (&p.retrace_args, [1, 1, 1], None),
            (&p.retrace_list, whole_list, list(0)),
            (&p.finish, [gx, gy, 1], None),
            (&p.rates, [1, 1, 1], None),
            (&p.select, [gx, gy, 1], None),
            (&p.shade_args, [1, 1, 1], None),
            (&p.shade, whole_list, list(1)),
            (&p.reconstruct, [gx, gy, 1], None),
        ];
        for (i, d) in STAGE_DISPATCHES[stage].clone().enumerate() {
            let (pipeline, [x, y, z], list) = dispatches[d];
            let indirect = list.filter(|_| self.indirect);
            if let Some((offset, word)) = indirect {
                timed.encoder().copy_buffer_to_buffer(
                    &self.work,
                    word * 4,
                    &self.list_args,
                    offset,
                    12,
                );
            }
            timed.pass(i, |pass| {
                self.frame.bind(gpu, scene, pass);
                pass.set_bind_group(2, bind_group, &[]);
                pass.set_pipeline(&pipeline.get());
                match indirect {
                    Some((offset, _)) => pass.dispatch_workgroups_indirect(&self.list_args, offset),
                    None => pass.dispatch_workgroups(x, y, z),
                }
            })?;
        }
        if stage == PASSES.len() - 1 {
            let encoder = timed.encoder();
            self.out_readback.record(encoder, &self.out, 0);
            self.header_readback.record(encoder, &self.work, 0);
        }
        let times = timed.submit()?;
        if let Some((_, _, all)) = &mut self.pending {
            all.extend(times);
        }
        Ok(())
    }

    /// Ends the frame after its four stages: swaps the caches and reads the image and counters.
    pub fn finish_frame(&mut self, gpu: &Gpu) -> Result<CacheFrame, RenderError> {
        let Some((_, _, dispatch_timings)) = self.pending.take() else {
            return Err(RenderError::Settings(
                "sample cache: finish_frame before begin_frame".into(),
            ));
        };
        let s = &self.settings;
        let mut timings = Vec::new();
        for t in &dispatch_timings {
            let pass = t.pass.split('/').next().unwrap_or(&t.pass);
            render::timing::merge(
                &mut timings,
                vec![PassTiming { pass: pass.into(), ..t.clone() }],
            );
        }
        self.current = 1 - self.current;
        self.frames += 1;

        let out: Vec<GpuPixel> = self.out_readback.read(gpu)?;
        let header: Vec<u32> = self.header_readback.read(gpu)?;
        let stats = CacheStats {
            shaded: header[0],
            rays: header[1],
            all_rays: header[34],
            new_samples: header[2],
            purged: header[3],
            reprojected: header[4],
            dropped: header[5],
            visible: header[12],
            occupied: header[13],
            base_shaded: header[14],
            slope_flagged: header[15],
            retrace_listed: header[33],
            list_args: [0, 1].map(|l| {
                let at = [RETRACE_ARGS_WORD, SHADE_ARGS_WORD][l] as usize;
                [header[at], header[at + 1], header[at + 2]]
            }),
            importance_bounds: (f32::from_bits(header[8]), f32::from_bits(header[9])),
            histogram: header[16..16 + s.buckets as usize].to_vec(),
            threshold: header[10],
            coin: f32::from_bits(header[11]),
        };
        Ok(CacheFrame {
            radiance: out.iter().map(|p| p.radiance).collect(),
            motion: out.iter().map(|p| p.motion).collect(),
            flags: out.iter().map(|p| p.flags).collect(),
            stats,
            timings,
            dispatch_timings,
        })
    }

    /// Reads back the cache the last frame produced.
    pub fn read_state(&self, gpu: &Gpu) -> Result<CacheState, RenderError> {
        let cache = &self.caches[self.current];
        let masks = read_pod(gpu, &cache.mask, "ssc masks")?;
        let slots = read_pod(gpu, &cache.slots, "ssc slots")?;
        Ok(CacheState { masks, slots })
    }

    /// Replaces the cache the next frame reprojects (tests: a state built to exercise one
    /// decision). `state` must hold one mask per pixel and `slots` slots per pixel.
    pub fn write_state(&mut self, gpu: &Gpu, state: &CacheState) -> Result<(), RenderError> {
        let pixels = (self.width * self.height) as usize;
        let n = self.settings.slots as usize;
        if state.masks.len() != pixels || state.slots.len() != n * pixels {
            return Err(RenderError::Settings(format!(
                "sample cache state: {} masks and {} slots, expected {pixels} and {}",
                state.masks.len(),
                state.slots.len(),
                n * pixels
            )));
        }
        let cache = &self.caches[self.current];
        gpu.queue.write_buffer(&cache.mask, 0, bytemuck::cast_slice(&state.masks));
        gpu.queue.write_buffer(&cache.slots, 0, bytemuck::cast_slice(&state.slots));
        Ok(())
    }

    /// Stale visibility of the last frame: how many samples the cache holds as visible that a
    /// retrace from the current camera finds occluded (what `Multi` would correct). Traces one
    /// ray per visible sample; for tests and diagnostics, outside the timed passes.
    pub fn audit(&self, gpu: &Gpu, scene: &SceneGpu) -> Result<u32, RenderError> {
        let mut encoder = gpu
            .device
            .create_command_encoder(&wgpu::CommandEncoderDescriptor { label: Some("ssc audit") });
        encoder.clear_buffer(&self.work, AUDIT_WORD * 4, Some(4));
        {
            let mut pass = encoder.begin_compute_pass(&wgpu::ComputePassDescriptor {
                label: Some("audit"),
                timestamp_writes: None,
            });
            self.frame.bind(gpu, scene, &mut pass);
            // The bind group whose destination is the cache the last frame wrote.
            pass.set_bind_group(2, &self.bind_groups[1 - self.current], &[]);
            pass.set_pipeline(&self.pipelines.audit.get());
            pass.dispatch_workgroups(
                self.width.div_ceil(8),
                self.height.div_ceil(8),
                self.settings.slots,
            );
        }
        self.header_readback.record(&mut encoder, &self.work, 0);
        gpu.queue.submit([encoder.finish()]);
        let header: Vec<u32> = self.header_readback.read(gpu)?;
        Ok(header[AUDIT_WORD as usize])
    }

    /// TAA's resolve (`taa`, its own submission) over the last frame's image, with each pixel's
    /// closest visible sample's primary attributes (reconstruct.wgsl) for its reprojection and
    /// history rejection: the paper applies TAA to every method for its error figures. The
    /// resolve reads no jitter: the cache's samples lie anywhere in their pixels.
    pub fn resolve_taa(
        &self,
        gpu: &Gpu,
        taa: &mut taa::Taa,
    ) -> Result<taa::TaaOutput, RenderError> {
        let (colour, primary) = (&self.colour, &self.primary);
        taa.resolve_external(gpu, [0.5; 2], |encoder, current, taa_primary| {
            encoder.copy_buffer_to_buffer(colour, 0, current, 0, colour.size());
            encoder.copy_buffer_to_buffer(primary, 0, taa_primary, 0, primary.size());
        })
    }

    pub fn layout(&self) -> &wgpu::BindGroupLayout {
        &self.layout
    }
}

fn tan_half_fov(scene: &SceneGpu) -> f32 {
    (0.5 * scene.camera().vfov).tan()
}

pub mod plugin;
pub mod recorded;
pub use plugin::Plugin;
