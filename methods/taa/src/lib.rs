//! Temporal anti-aliasing (TAA) over jittered 1 spp path tracing: the temporal baseline.
//!
//! Two passes per frame:
//! - `taa_trace` (methods/taa/shaders/trace.wgsl, after the shading library): one path per pixel
//!   through the frame's Halton (2, 3) jitter point ([`jitter`]), plus that sample's own primary
//!   hit (depth, normal, instance, motion, depth from the previous camera);
//! - `taa_resolve` (shaders/resolve.wgsl): reprojection of the history by the motion
//!   vector (bilinear), history rejection on disocclusion (instance, relative depth and normal
//!   test at the previous position), neighbourhood clamp (3x3 min/max, or variance clipping
//!   mean +- gamma sigma), exponential blend with weight max(alpha, 1 / (length + 1)).
//!
//! History colour and primary attributes are ping-ponged; [`resolve_cpu`] repeats the resolve
//! on the CPU for tests. The resolve can also run over another method's colour
//! ([`Taa::resolve_external`]): the hash cache uses it as the paper does.
//!
//! Choices and departures from the usual real-time TAA (Karis 2014, Yang et al. 2020):
//! - the blend starts as a uniform average (weight 1 / (length + 1)) and becomes exponential at
//!   alpha, so a still image converges to the mean instead of starting from one frame's
//!   weight 1 - alpha; the paper's temporal weights of Philippi et al. [PFJ23] are not used;
//! - history is sampled bilinearly (no Catmull-Rom), clamped in linear RGB (no YCoCg, no
//!   luminance weighting), and rejected on a nearest-pixel test of instance, depth seen from
//!   the previous camera and normal;
//! - each sample carries its own primary hit (the jittered ray's), not the pixel-centre
//!   G-buffer of the path tracer: motion vectors and rejection describe what was shaded;
//! - the primary ray is traced twice (once for its attributes, once inside `path_radiance`).
//!
//! Cost (lavapipe on 2 shared CPU cores, courtyard 320x180, max depth 4, median GPU ms of 5
//! frames, an earlier courtyard version of cache_methods_bench): taa_trace 1034, taa_resolve 11.
//! Hairball 320x180, max depth 3, mean of 10 frames on an idle machine (`cargo run -j2 -p bench
//! --example cache_methods_bench -- 320 180 12`, table in docs/lab/sample-cache-fig7.md):
//! taa_trace 912, taa_resolve 10.8; 191 905 rays per frame (GPU counter).

pub mod jitter;
pub mod resolve_cpu;

use render::compute::BufferBinding;
use render::error::RenderError;
use render::frame_bindings::FrameBindings;
use render::gpu::Gpu;
use render::gpu_struct::GpuStruct;
use render::pass_library::PassLibrary;
use render::readback::{copy_all, read_pod};
use render::scene_gpu::SceneGpu;
use render::shader::{Module, Program};
use render::timing::{PassTimer, PassTiming};

pub use jitter::{halton, halton_jitter};

pub const TAA_TRACE_PASS: &str = "taa_trace";
pub const TAA_RESOLVE_PASS: &str = "taa_resolve";

/// TAA's structs (`TaaParams`, `TaaPrimary`), importable as `flicker::taa_types`.
pub fn types_module() -> Module {
    Module::generated("package::taa_types", &[TaaParams::WGSL, TaaPrimary::WGSL])
}

/// The primary-hit attributes shared by TAA and the hash cache (`flicker::taa_primary`).
pub fn primary_module() -> Module {
    render::wgsl_file!("primary.wgsl")
}

const WORKGROUP: u32 = 8;

/// How the reprojected history is limited to the current neighbourhood.
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
pub enum TaaClamp {
    /// No clamp: ghosting wherever the rejection test passes wrongly (for tests).
    None,
    /// Per-channel min/max of the 3x3 neighbourhood (Karis 2014).
    MinMax,
    /// Clip towards the 3x3 mean inside mean +- gamma * sigma (Salvi 2016).
    Variance { gamma: f32 },
}

/// The `Taa(...)` method's scenario settings; every field defaults to [`Default`]'s value.
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct TaaSettings {
    /// Weight of the current frame in the exponential blend.
    pub alpha: f32,
    pub clamp: TaaClamp,
    /// Points of the Halton (2, 3) cycle; 0 = rays through pixel centres.
    pub jitter_length: u32,
    /// History rejected where the previous depth differs by more than this fraction.
    pub depth_tolerance: f32,
    /// History rejected where the normals' cosine is below this.
    pub normal_threshold: f32,
    /// Cap of the history length, the denominator of the uniform-average start.
    pub max_history: f32,
}

impl Default for TaaSettings {
    fn default() -> Self {
        Self {
            alpha: 0.1,
            clamp: TaaClamp::Variance { gamma: 1.0 },
            jitter_length: 8,
            depth_tolerance: 0.05,
            normal_threshold: 0.8,
            max_history: 256.0,
        }
    }
}

impl TaaSettings {
    pub fn validate(&self) -> Result<(), RenderError> {
        if !(self.alpha > 0.0 && self.alpha <= 1.0) {
            return Err(RenderError::Settings(format!(
                "TAA alpha must be in (0, 1], got {}",
                self.alpha
            )));
        }
        if let TaaClamp::Variance { gamma } = self.clamp
            && !(gamma > 0.0)
        {
            return Err(RenderError::Settings(format!(
                "TAA variance clipping gamma must be positive, got {gamma}"
            )));
        }
        if !(self.depth_tolerance > 0.0) || !(self.max_history >= 1.0) {
            return Err(RenderError::Settings(
                "TAA depth_tolerance must be positive and max_history at least 1".into(),
            ));
        }
        Ok(())
    }

    pub(crate) fn params(
        &self,
        width: u32,
        height: u32,
        jitter: [f32; 2],
        history_valid: bool,
    ) -> TaaParams {
        let (clamp_mode, gamma) = match self.clamp {
            TaaClamp::None => (0, 0.0),
            TaaClamp::MinMax => (1, 0.0),
            TaaClamp::Variance { gamma } => (2, gamma),
        };
        TaaParams {
            jitter,
            alpha: self.alpha,
            gamma,
            size: [width, height],
            clamp_mode,
            history_valid: history_valid as u32,
            depth_tolerance: self.depth_tolerance,
            normal_threshold: self.normal_threshold,
            max_history: self.max_history,
            pad: 0.0,
        }
    }
}

/// The trace pass's own @group(2) (declared into its WGSL).
const TRACE_GROUP: [BufferBinding; 4] = [
    BufferBinding::read("taa", "TaaParams"),
    BufferBinding::read_write("taa_current", "array<vec4f>"),
    BufferBinding::read_write("taa_primary", "array<TaaPrimary>"),
    // [0]: rays traced by this pass (sg_rays_traced of every invocation).
    BufferBinding::read_write("taa_counters", "array<atomic<u32>>"),
];

/// The resolve pass's @group(0) (declared into its WGSL).
const RESOLVE_GROUP: [BufferBinding; 6] = [
    BufferBinding::read("taa", "TaaParams"),
    BufferBinding::read("current", "array<vec4f>"),
    BufferBinding::read("primary", "array<TaaPrimary>"),
    BufferBinding::read("previous_primary", "array<TaaPrimary>"),
    BufferBinding::read("history", "array<vec4f>"),
    BufferBinding::read_write("resolved", "array<vec4f>"),
];

render::gpu_struct! {
    /// TAA's parameters, shared by its trace and resolve passes (and the hash cache's).
    pub struct TaaParams {
        /// Position of the primary ray inside its pixel, [0, 1)^2.
        pub jitter: [f32; 2] => "vec2f",
        /// Exponential blend weight of the current frame.
        pub alpha: f32 => "f32",
        /// Variance clipping: box = mean +- gamma * sigma.
        pub gamma: f32 => "f32",
        pub size: [u32; 2] => "vec2u",
        /// 0 none, 1 min/max, 2 variance clipping.
        pub clamp_mode: u32 => "u32",
        /// 0 on the first frame: everything is rejected.
        pub history_valid: u32 => "u32",
        /// Relative.
        pub depth_tolerance: f32 => "f32",
        /// Minimum cosine between current and history normals.
        pub normal_threshold: f32 => "f32",
        /// Cap of the history length (frames).
        pub max_history: f32 => "f32",
        pub pad: f32 => "f32",
    }
}

render::gpu_struct! {
    /// The attributes of a jittered sample's primary hit (TAA's trace, the hash cache).
    #[derive(Default, PartialEq)]
    pub struct TaaPrimary {
        pub normal: [f32; 3] => "vec3f",
        /// Distance from the camera; 0 on a miss.
        pub depth: f32 => "f32",
        /// Previous image position minus current one, pixels (x right, y down).
        pub motion: [f32; 2] => "vec2f",
        /// [`render::path_tracer::NO_HIT`] on a miss.
        pub instance: u32 => "u32",
        /// Distance from the previous camera to where the point was in the previous frame.
        pub previous_depth: f32 => "f32",
    }
}

const _: () = assert!(size_of::<TaaParams>() == 48 && size_of::<TaaPrimary>() == 32);

/// One resolved frame.
#[derive(Clone, Debug, Default)]
pub struct TaaOutput {
    /// Resolved linear radiance, row-major, alpha = 1.
    pub radiance: Vec<[f32; 4]>,
    /// Motion of each pixel's sample (previous minus current position, pixels).
    pub motion: Vec<[f32; 2]>,
    /// Frames accumulated in each pixel's history (1 = rejected or first frame).
    pub history_length: Vec<f32>,
    /// [`TAA_TRACE_PASS`] (when traced here) and [`TAA_RESOLVE_PASS`].
    pub timings: Vec<PassTiming>,
    /// Rays the trace pass traced (primary-attribute ray + the path's camera, shadow and
    /// bounce rays), counted on the GPU; 0 for [`Taa::resolve_external`].
    pub rays: u64,
    /// Paths shaded: one per pixel; 0 for [`Taa::resolve_external`].
    pub shaded: u64,
}

/// Everything the last resolve read and wrote, for checking it against [`resolve_cpu`].
#[derive(Clone, Debug)]
pub struct TaaInspection {
    pub params_history_valid: bool,
    pub current: Vec<[f32; 4]>,
    pub primary: Vec<TaaPrimary>,
    pub previous_primary: Vec<TaaPrimary>,
    pub history: Vec<[f32; 4]>,
    pub resolved: Vec<[f32; 4]>,
}

pub struct Taa {
    settings: TaaSettings,
    width: u32,
    height: u32,
    params: wgpu::Buffer,
    current: wgpu::Buffer,
    /// Ping-pong: `primary[parity]` and `history[parity]` are written this frame.
    primary: [wgpu::Buffer; 2],
    history: [wgpu::Buffer; 2],
    /// The trace pass's frame parameters and scene group.
    frame: FrameBindings,
    trace_layout: wgpu::BindGroupLayout,
    trace_pipeline: render::pass_library::LibraryPipeline,
    resolve_groups: [wgpu::BindGroup; 2],
    resolve_pipeline: wgpu::ComputePipeline,
    /// [0]: rays traced by the trace pass this frame.
    counters: wgpu::Buffer,
    /// The trace pass's timer, and the resolve's (each pass is its own submission).
    timer: PassTimer,
    resolve_timer: PassTimer,
    parity: usize,
    history_valid: bool,
    last_history_valid: bool,
}

impl Taa {
    /// Passes at the scene's resolution, bound to its scene and geometry layouts.
    pub fn new(gpu: &Gpu, scene: &SceneGpu, settings: TaaSettings) -> Result<Self, RenderError> {
        settings.validate()?;
        let s = scene.settings();
        let (width, height) = (s.width, s.height);
        gpu.check_resolution(width, height, 16 * 3 + 32 * 2)?;
        // Neither pass declares var<workgroup>.
        gpu.check_workgroup_memory(TAA_RESOLVE_PASS, 0)?;
        let device = &gpu.device;
        let pixels = width as u64 * height as u64;
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
        let params = buffer(
            "taa params",
            size_of::<TaaParams>() as u64,
            wgpu::BufferUsages::STORAGE | wgpu::BufferUsages::COPY_DST,
        );
        let current = buffer("taa current", pixels * 16, rw);
        let primary =
            [buffer("taa primary 0", pixels * 32, rw), buffer("taa primary 1", pixels * 32, rw)];
        let history =
            [buffer("taa history 0", pixels * 16, rw), buffer("taa history 1", pixels * 16, rw)];
        let counters = buffer("taa ray counter", 16, rw);

        let (trace_layout, [trace_pipeline]) = scene.library_pass(
            gpu,
            "taa_trace.wgsl",
            Self::trace_program(),
            &TRACE_GROUP,
            ["taa_trace"],
        )?;
        let resolve_layout = render::compute::binding_layout(gpu, "taa resolve", &RESOLVE_GROUP);
        let [resolve_pipeline] = render::compute::pipelines(
            gpu,
            "taa_resolve.wgsl",
            &Self::resolve_program(),
            &[&resolve_layout],
            ["taa_resolve"],
        )?;
        let resolve_group = |p: usize| {
            let q = 1 - p;
            render::compute::buffer_group(
                gpu,
                "taa resolve",
                &resolve_layout,
                &[&params, &current, &primary[p], &primary[q], &history[q], &history[p]],
            )
        };
        let resolve_groups = [resolve_group(0), resolve_group(1)];
        Ok(Self {
            settings,
            width,
            height,
            params,
            current,
            primary,
            history,
            frame: FrameBindings::new(gpu, scene),
            trace_layout,
            trace_pipeline,
            resolve_groups,
            resolve_pipeline,
            counters,
            timer: PassTimer::new(gpu, &[TAA_TRACE_PASS]),
            resolve_timer: PassTimer::new(gpu, &[TAA_RESOLVE_PASS]),
            parity: 0,
            history_valid: false,
            last_history_valid: false,
        })
    }

    /// The resolve pass's program: TAA's structs, its @group(0), shaders/resolve.wgsl.
    fn resolve_program() -> Program {
        let types = types_module();
        let bindings = render::compute::group_module(
            "package::taa_resolve_bindings",
            0,
            &RESOLVE_GROUP,
            &[&types],
        );
        Program::new(vec![types, bindings, PassLibrary::module("package::kernel")])
            .entry(render::wgsl_file!("resolve.wgsl"))
    }

    /// The trace pass's program: the shading library, TAA's structs, the primary attributes, its
    /// @group(2), shaders/trace.wgsl.
    pub fn trace_program() -> &'static Program {
        static PROGRAM: std::sync::OnceLock<Program> = std::sync::OnceLock::new();
        PROGRAM.get_or_init(|| {
            let types = types_module();
            let bindings = render::compute::group_module(
                "package::taa_trace_bindings",
                2,
                &TRACE_GROUP,
                &[&types],
            );
            PassLibrary::program(
                [types, primary_module(), bindings],
                [render::wgsl_file!("trace.wgsl")],
            )
        })
    }

    pub fn settings(&self) -> TaaSettings {
        self.settings
    }

    /// Forgets the history: the next frame starts a new one.
    pub fn reset(&mut self) {
        self.history_valid = false;
    }

    /// Jittered 1 spp path tracing + resolve. `scene` must be updated to this frame's scene.
    pub fn render(
        &mut self,
        gpu: &Gpu,
        scene: &SceneGpu,
        seed: u64,
        frame: u32,
    ) -> Result<TaaOutput, RenderError> {
        let trace = self.trace(gpu, scene, seed, frame)?;
        self.resolve(gpu, trace)
    }

    /// The trace pass (its own submission): jittered 1 spp path tracing into the current colour.
    pub fn trace(
        &mut self,
        gpu: &Gpu,
        scene: &SceneGpu,
        seed: u64,
        frame: u32,
    ) -> Result<Vec<PassTiming>, RenderError> {
        let jitter = halton_jitter(frame, self.settings.jitter_length);
        self.frame.prepare(gpu, scene, 1, 0, seed, frame);
        self.write_params(gpu, jitter);
        let group = self.trace_group(gpu, &self.current, &self.primary[self.parity]);
        let mut timed = self.timer.begin(gpu, "taa trace");
        timed.encoder().clear_buffer(&self.counters, 0, None);
        timed.pass(0, |pass| {
            pass.set_pipeline(&self.trace_pipeline.get());
            self.frame.bind(gpu, scene, pass);
            pass.set_bind_group(2, &group, &[]);
            pass.dispatch_workgroups(
                self.width.div_ceil(WORKGROUP),
                self.height.div_ceil(WORKGROUP),
                1,
            );
        })?;
        timed.submit()
    }

    /// The resolve pass after [`Self::trace`] (its own submission): reprojection, clamp, blend;
    /// `trace` is what `trace` returned, reported first in the output's timings.
    pub fn resolve(&mut self, gpu: &Gpu, trace: Vec<PassTiming>) -> Result<TaaOutput, RenderError> {
        let mut timed = self.resolve_timer.begin(gpu, "taa resolve");
        timed.pass(0, |pass| self.encode_resolve(pass))?;
        let mut timings = trace;
        timings.extend(timed.submit()?);
        let mut out = self.finish(gpu, timings)?;
        out.rays = read_pod::<u32>(gpu, &self.counters, "TAA ray counter")?[0] as u64;
        out.shaded = self.width as u64 * self.height as u64;
        Ok(out)
    }

    /// The bind group of the trace pass's @group(2) writing `current` and `primary`; other
    /// passes that feed the resolve (the hash cache) bind the same layout.
    fn trace_group(
        &self,
        gpu: &Gpu,
        current: &wgpu::Buffer,
        primary: &wgpu::Buffer,
    ) -> wgpu::BindGroup {
        render::compute::buffer_group(
            gpu,
            "taa trace",
            &self.trace_layout,
            &[&self.params, current, primary, &self.counters],
        )
    }

    /// Resolves a colour another pass produced: `write` gets an encoder, the buffer to write the
    /// linear colour into (vec4 per pixel) and the one for [`TaaPrimary`] texels, and records
    /// untimed commands (copies; the producer times its own passes); the resolve follows in the
    /// same submission.
    pub fn resolve_external(
        &mut self,
        gpu: &Gpu,
        jitter: [f32; 2],
        write: impl FnOnce(&mut wgpu::CommandEncoder, &wgpu::Buffer, &wgpu::Buffer),
    ) -> Result<TaaOutput, RenderError> {
        self.write_params(gpu, jitter);
        let mut timed = self.resolve_timer.begin(gpu, "taa resolve");
        write(timed.encoder(), &self.current, &self.primary[self.parity]);
        timed.pass(0, |pass| self.encode_resolve(pass))?;
        let timings = timed.submit()?;
        self.finish(gpu, timings)
    }

    /// Resolves a colour and primary hits held on the CPU (a pass that reads its image back,
    /// e.g. the SSS method): uploads both and runs [`Self::resolve_external`].
    pub fn resolve_colour(
        &mut self,
        gpu: &Gpu,
        jitter: [f32; 2],
        colour: &[[f32; 4]],
        primary: &[TaaPrimary],
    ) -> Result<TaaOutput, RenderError> {
        let pixels = (self.width * self.height) as usize;
        if colour.len() != pixels || primary.len() != pixels {
            return Err(RenderError::Settings(format!(
                "TAA resolve of {} colours and {} primary hits; expected {pixels} ({}x{})",
                colour.len(),
                primary.len(),
                self.width,
                self.height
            )));
        }
        let init = |label: &str, contents: &[u8]| {
            gpu.buffer_init(label, contents, wgpu::BufferUsages::COPY_SRC)
        };
        let (c, p) = (
            init("taa external colour", bytemuck::cast_slice(colour)),
            init("taa external primary", bytemuck::cast_slice(primary)),
        );
        self.resolve_external(gpu, jitter, |encoder, colour, primary| {
            encoder.copy_buffer_to_buffer(&c, 0, colour, 0, c.size());
            encoder.copy_buffer_to_buffer(&p, 0, primary, 0, p.size());
        })
    }

    fn write_params(&mut self, gpu: &Gpu, jitter: [f32; 2]) {
        let params = self.settings.params(self.width, self.height, jitter, self.history_valid);
        gpu.queue.write_buffer(&self.params, 0, bytemuck::bytes_of(&params));
        self.last_history_valid = self.history_valid;
    }

    fn encode_resolve(&self, pass: &mut wgpu::ComputePass<'_>) {
        pass.set_pipeline(&self.resolve_pipeline);
        pass.set_bind_group(0, &self.resolve_groups[self.parity], &[]);
        pass.dispatch_workgroups(
            self.width.div_ceil(WORKGROUP),
            self.height.div_ceil(WORKGROUP),
            1,
        );
    }

    /// Reads the resolved frame and motion, then swaps the ping-pong buffers.
    fn finish(&mut self, gpu: &Gpu, timings: Vec<PassTiming>) -> Result<TaaOutput, RenderError> {
        let [resolved, primary] = copy_all(
            gpu,
            [
                (&self.history[self.parity], "TAA resolved colour"),
                (&self.primary[self.parity], "TAA primary hits"),
            ],
        );
        let resolved: Vec<[f32; 4]> = resolved.read(gpu)?;
        let primary: Vec<TaaPrimary> = primary.read(gpu)?;
        self.parity = 1 - self.parity;
        self.history_valid = true;
        Ok(TaaOutput {
            radiance: resolved.iter().map(|c| [c[0], c[1], c[2], 1.0]).collect(),
            history_length: resolved.iter().map(|c| c[3]).collect(),
            motion: primary.iter().map(|p| p.motion).collect(),
            timings,
            rays: 0,
            shaded: 0,
        })
    }

    /// Inputs and output of the last resolve (call right after `render`).
    pub fn inspect(&self, gpu: &Gpu) -> Result<TaaInspection, RenderError> {
        let last = 1 - self.parity;
        Ok(TaaInspection {
            params_history_valid: self.last_history_valid,
            current: read_pod(gpu, &self.current, "TAA current")?,
            primary: read_pod(gpu, &self.primary[last], "TAA primary")?,
            previous_primary: read_pod(gpu, &self.primary[self.parity], "TAA previous primary")?,
            history: read_pod(gpu, &self.history[self.parity], "TAA history")?,
            resolved: read_pod(gpu, &self.history[last], "TAA resolved")?,
        })
    }
}

pub mod plugin;
pub use plugin::Plugin;
