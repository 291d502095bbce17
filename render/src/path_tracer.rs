//! The WGSL path tracer: per frame, HDR radiance and a primary-hit G-buffer read back to the
//! CPU, GPU time per pass; and converged references accumulated in bounded batches.
//!
//! A method like the others: it reads the scene on the GPU (`SceneGpu`: the tables, the geometry
//! and the pass library), binds them at @group(0) and @group(1) with its own frame parameters
//! (`FrameBindings`), and owns its outputs (@group(2) of render/shaders/path_tracer.wgsl: radiance
//! sum, G-buffer, sample partials, ray counter). Whoever renders with it (the path tracing
//! method, the references, the SSS method) holds its own.

use crate::compute::{self, BufferBinding};
use crate::error::RenderError;
use crate::frame_bindings::FrameBindings;
use crate::gpu::Gpu;
use crate::gpu_struct::GpuStruct;
use crate::pass_library::{LibraryPipeline, PassLibrary};
use crate::readback::Staging;
use crate::scene_gpu::SceneGpu;
use crate::shader::{Module, Program};
use crate::timing::{PassTimer, PassTiming, merge};

/// `Hit::instance`/`primitive` of a pixel whose primary ray left the scene.
pub const NO_HIT: u32 = u32::MAX;

/// Paths (pixels x samples) one dispatch may trace, so that no submission runs long enough to
/// trip a GPU watchdog (about 2 s on desktop drivers) even on slow adapters.
pub const PATHS_PER_DISPATCH: u64 = 1 << 20;

/// Samples one invocation of the trace pass traces; a dispatch spreads its samples over
/// workgroup z (see trace_main in path_tracer.wgsl for why invocations must stay short). An
/// invocation starts its next sample's path as soon as one ends (path regeneration), so more
/// samples per invocation keep its lanes busier (2 before regeneration; docs/lab/render-speed.md), while
/// an invocation stays far below llvmpipe's loop cap.
pub const SAMPLES_PER_THREAD: u32 = 8;

/// Upper bound on sample chunks (workgroups along z) per dispatch.
const MAX_CHUNKS: u32 = 4096;

/// The pass names in [`FrameOutput::timings`].
pub const GBUFFER_PASS: &str = "gbuffer";
pub const PATH_TRACE_PASS: &str = "path_trace";

const WORKGROUP: u32 = 8;
/// Words of the ray counter: [0] rays traced since the last clear.
const COUNTER_WORDS: u64 = 4;

pub use crate::pass_library::LIBRARY_STORAGE_BUFFERS;

pub use crate::scene_gpu::PathTracerSettings;

/// Primary-hit attributes of the pixel-centre ray, row-major, `width * height` each.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct GBuffer {
    /// Distance from the camera to the hit along the ray; `f32::INFINITY` on a miss.
    pub depth: Vec<f32>,
    /// World shading normal turned towards the camera; zero on a miss.
    pub normal: Vec<[f32; 3]>,
    /// Linear base colour at the hit (texture included); zero on a miss.
    pub albedo: Vec<[f32; 3]>,
    /// Pixel offset from where the point is now to where it was in the previous rendered frame
    /// (previous camera and instance transform); x right, y down. Misses: the offset of the
    /// direction at infinity (camera rotation only).
    pub motion: Vec<[f32; 2]>,
    /// Index into `SceneDesc::instances`; [`NO_HIT`] on a miss.
    pub instance_id: Vec<u32>,
    /// Triangle index in the instance's mesh; [`NO_HIT`] on a miss.
    pub primitive_id: Vec<u32>,
}

#[derive(Clone, Debug, Default, PartialEq)]
pub struct FrameOutput {
    pub width: u32,
    pub height: u32,
    /// Linear HDR radiance, mean of the frame's samples, row-major; alpha = 1.
    pub radiance: Vec<[f32; 4]>,
    pub gbuffer: GBuffer,
    /// One entry per pass: [`GBUFFER_PASS`], [`PATH_TRACE_PASS`] (readback excluded).
    pub timings: Vec<PassTiming>,
    /// Rays traced by both passes (G-buffer rays + camera, shadow and bounce rays of the paths),
    /// counted on the GPU.
    pub rays: u64,
    /// Paths shaded: pixels x spp.
    pub shaded: u64,
}

crate::gpu_struct! {
    /// One pixel of the path tracer's G-buffer (its @group(2) `gbuffer`).
    pub struct GBufferTexel {
        pub normal: [f32; 3] => "vec3f",
        pub depth: f32 => "f32",
        pub albedo: [f32; 3] => "vec3f",
        pub instance: u32 => "u32",
        pub motion: [f32; 2] => "vec2f",
        pub primitive: u32 => "u32",
        pub pad: u32 => "u32",
    }
}

const _: () = assert!(size_of::<GBufferTexel>() == 48);

/// Bytes per pixel of the per-pixel buffers (radiance sum and G-buffer texel).
const BYTES_PER_PIXEL: u64 = 16 + size_of::<GBufferTexel>() as u64;

pub struct PathTracer {
    settings: PathTracerSettings,
    frame: FrameBindings,
    /// The path tracer's own @group(2) and its buffers.
    layout: wgpu::BindGroupLayout,
    bind_group: wgpu::BindGroup,
    trace_pipeline: LibraryPipeline,
    gbuffer_pipeline: LibraryPipeline,
    radiance_sum: wgpu::Buffer,
    gbuffer: wgpu::Buffer,
    /// Per-(chunk, pixel) sums of one dispatch, summed by `accumulate_main`.
    sample_partials: wgpu::Buffer,
    accumulate_pipeline: LibraryPipeline,
    max_chunks: u32,
    radiance_readback: Staging,
    gbuffer_readback: Staging,
    timer: PassTimer,
    /// Rays traced (atomic, flushed once per invocation), cleared per frame.
    counters: wgpu::Buffer,
    counters_readback: Staging,
    paths_per_dispatch: u64,
}

impl PathTracer {
    /// Its outputs at the scene's resolution and its passes from the scene's library.
    pub fn new(gpu: &Gpu, scene: &SceneGpu) -> Result<Self, RenderError> {
        let settings = scene.settings();
        gpu.check_resolution(settings.width, settings.height, BYTES_PER_PIXEL)?;
        // Before any buffer is made; `PassLibrary::pass` checks again when it builds the pass.
        PassLibrary::check_storage_bindings(gpu, "path_tracer.wgsl", &OWN_GROUP)?;
        // No workgroup memory is declared (var<workgroup>): nothing to check against the budget.
        gpu.check_workgroup_memory("path_trace", 0)?;

        let device = &gpu.device;
        let pixels = settings.width as u64 * settings.height as u64;
        let per_pixel = |label: &str, size: u64, usage: wgpu::BufferUsages| {
            device.create_buffer(&wgpu::BufferDescriptor {
                label: Some(label),
                size,
                usage,
                mapped_at_creation: false,
            })
        };
        let rw = wgpu::BufferUsages::STORAGE | wgpu::BufferUsages::COPY_SRC;
        let radiance_size = pixels * 16;
        let gbuffer_size = pixels * size_of::<GBufferTexel>() as u64;
        let radiance_sum = per_pixel("radiance sum", radiance_size, rw);
        let gbuffer = per_pixel("gbuffer", gbuffer_size, rw);
        let radiance_readback = Staging::new(gpu, "radiance", radiance_size);
        let gbuffer_readback = Staging::new(gpu, "gbuffer", gbuffer_size);
        let max_chunks = MAX_CHUNKS.min(gpu.limits.max_compute_workgroups_per_dimension);
        let sample_partials = Self::partials_buffer(
            gpu,
            pixels,
            Self::chunks_for(PATHS_PER_DISPATCH, pixels, max_chunks),
        )?;
        let counters = per_pixel(
            "path tracer ray counter",
            COUNTER_WORDS * 4,
            rw | wgpu::BufferUsages::COPY_DST,
        );
        let counters_readback = Staging::new(gpu, "ray counter", COUNTER_WORDS * 4);

        let (layout, [trace_pipeline, gbuffer_pipeline, accumulate_pipeline]) = scene
            .library_pass(
                gpu,
                "path_tracer.wgsl",
                Self::program(),
                &OWN_GROUP,
                ["trace_main", "gbuffer_main", "accumulate_main"],
            )?;
        let bind_group = compute::buffer_group(
            gpu,
            "path tracer",
            &layout,
            &[&radiance_sum, &gbuffer, &sample_partials, &counters],
        );
        Ok(Self {
            settings,
            frame: FrameBindings::new(gpu, scene),
            layout,
            bind_group,
            trace_pipeline,
            gbuffer_pipeline,
            radiance_sum,
            gbuffer,
            sample_partials,
            accumulate_pipeline,
            max_chunks,
            radiance_readback,
            gbuffer_readback,
            timer: PassTimer::new(gpu, &[GBUFFER_PASS, PATH_TRACE_PASS]),
            counters,
            counters_readback,
            paths_per_dispatch: PATHS_PER_DISPATCH,
        })
    }

    /// The path tracer's program: the library, its own structs and @group(2), path_tracer.wgsl.
    pub fn program() -> &'static Program {
        static PROGRAM: std::sync::OnceLock<Program> = std::sync::OnceLock::new();
        PROGRAM.get_or_init(|| {
            let types = Module::generated(
                "package::path_tracer_types",
                &[
                    GBufferTexel::WGSL,
                    &format!("const SAMPLES_PER_THREAD: u32 = {SAMPLES_PER_THREAD}u;"),
                ],
            );
            let bindings =
                compute::group_module("package::path_tracer_bindings", 2, &OWN_GROUP, &[&types]);
            PassLibrary::program([types, bindings], [crate::wgsl_file!("path_tracer.wgsl")])
        })
    }

    /// Every WGSL source of the pass: part of the key of anything cached from its images.
    pub fn shader_source() -> &'static str {
        static SOURCE: std::sync::OnceLock<String> = std::sync::OnceLock::new();
        SOURCE.get_or_init(|| Self::program().fingerprint())
    }

    /// Group 2 over the current buffers, after one of them was replaced.
    fn rebind(&mut self, gpu: &Gpu) {
        self.bind_group = compute::buffer_group(
            gpu,
            "path tracer",
            &self.layout,
            &[&self.radiance_sum, &self.gbuffer, &self.sample_partials, &self.counters],
        );
    }

    pub fn settings(&self) -> PathTracerSettings {
        self.settings
    }

    /// One frame: G-buffer of the pixel-centre rays, then `spp` jittered paths per pixel.
    pub fn render(
        &mut self,
        gpu: &Gpu,
        scene: &SceneGpu,
        spp: u32,
        seed: u64,
        frame: u32,
    ) -> Result<FrameOutput, RenderError> {
        if spp == 0 {
            return Err(RenderError::Settings("spp must be at least 1".into()));
        }
        // G-buffer pass.
        self.frame.prepare(gpu, scene, 0, 0, seed, frame);
        let mut timed = self.timer.begin(gpu, "gbuffer");
        timed.encoder().clear_buffer(&self.counters, 0, None);
        timed.pass(0, |pass| {
            pass.set_pipeline(&self.gbuffer_pipeline.get());
            self.frame.bind(gpu, scene, pass);
            pass.set_bind_group(2, &self.bind_group, &[]);
            pass.dispatch_workgroups(
                self.settings.width.div_ceil(WORKGROUP),
                self.settings.height.div_ceil(WORKGROUP),
                1,
            );
        })?;
        let mut timings = timed.submit()?;

        // Path-trace pass, in batches of bounded work.
        merge(&mut timings, self.trace_batches(gpu, scene, spp, seed, frame, &mut |_, _| {})?);

        let radiance = self.read_radiance(gpu)?;
        let gbuffer = self.read_gbuffer(gpu)?;
        let rays = self.read_rays(gpu)?;
        let shaded = self.settings.width as u64 * self.settings.height as u64 * spp as u64;
        Ok(FrameOutput {
            width: self.settings.width,
            height: self.settings.height,
            radiance,
            gbuffer,
            timings,
            rays,
            shaded,
        })
    }

    /// The current scene accumulated to `spp` samples per pixel in batches of at most
    /// [`PATHS_PER_DISPATCH`] paths, one submission each; `progress(done_spp, total_spp)` after
    /// every batch. Radiance only (no G-buffer).
    pub fn render_reference(
        &mut self,
        gpu: &Gpu,
        scene: &SceneGpu,
        spp: u32,
        seed: u64,
        frame: u32,
        progress: &mut dyn FnMut(u32, u32),
    ) -> Result<Vec<[f32; 4]>, RenderError> {
        if spp == 0 {
            return Err(RenderError::Settings("reference spp must be at least 1".into()));
        }
        self.trace_batches(gpu, scene, spp, seed, frame, progress)?;
        self.read_radiance(gpu)
    }

    /// Samples per pixel in one dispatch at this resolution (at least 1).
    pub fn samples_per_dispatch(&self) -> u32 {
        let pixels = self.settings.width as u64 * self.settings.height as u64;
        Self::chunks_for(self.paths_per_dispatch, pixels, self.max_chunks) * SAMPLES_PER_THREAD
    }

    /// Changes the work bound of one dispatch (default [`PATHS_PER_DISPATCH`]): lower it for a
    /// slow adapter with a watchdog, raise it for a fast one. The image does not depend on it
    /// beyond float summation order.
    pub fn set_paths_per_dispatch(&mut self, gpu: &Gpu, paths: u64) -> Result<(), RenderError> {
        self.paths_per_dispatch = paths.max(1);
        let pixels = self.settings.width as u64 * self.settings.height as u64;
        let chunks = Self::chunks_for(self.paths_per_dispatch, pixels, self.max_chunks);
        if self.sample_partials.size() < pixels * chunks as u64 * 16 {
            self.sample_partials = Self::partials_buffer(gpu, pixels, chunks)?;
            self.rebind(gpu);
        }
        Ok(())
    }

    /// Chunks of [`SAMPLES_PER_THREAD`] samples per dispatch: at least one.
    fn chunks_for(paths: u64, pixels: u64, max_chunks: u32) -> u32 {
        (paths / pixels / SAMPLES_PER_THREAD as u64).clamp(1, max_chunks as u64) as u32
    }

    fn partials_buffer(gpu: &Gpu, pixels: u64, chunks: u32) -> Result<wgpu::Buffer, RenderError> {
        let size = pixels * chunks as u64 * 16;
        gpu.check_buffer_size("sample partials", size)?;
        Ok(gpu.device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("sample partials"),
            size,
            usage: wgpu::BufferUsages::STORAGE,
            mapped_at_creation: false,
        }))
    }

    /// Traces `spp` samples into the radiance sum; returns the summed time of the batches.
    fn trace_batches(
        &self,
        gpu: &Gpu,
        scene: &SceneGpu,
        spp: u32,
        seed: u64,
        frame: u32,
        progress: &mut dyn FnMut(u32, u32),
    ) -> Result<Vec<PassTiming>, RenderError> {
        let per_dispatch = self.samples_per_dispatch();
        let mut done = 0;
        let mut timings = Vec::new();
        while done < spp {
            let batch = per_dispatch.min(spp - done);
            self.frame.write(gpu, scene, batch, done, seed, frame, done > 0);
            let mut timed = self.timer.begin(gpu, "path trace");
            timed.pass(1, |pass| {
                let (x, y) = (
                    self.settings.width.div_ceil(WORKGROUP),
                    self.settings.height.div_ceil(WORKGROUP),
                );
                self.frame.bind(gpu, scene, pass);
                pass.set_bind_group(2, &self.bind_group, &[]);
                pass.set_pipeline(&self.trace_pipeline.get());
                pass.dispatch_workgroups(x, y, batch.div_ceil(SAMPLES_PER_THREAD));
                pass.set_pipeline(&self.accumulate_pipeline.get());
                pass.dispatch_workgroups(x, y, 1);
            })?;
            merge(&mut timings, timed.submit()?);
            done += batch;
            progress(done, spp);
        }
        Ok(timings)
    }

    /// Rays the passes since the last clear traced (the frame's G-buffer and paths).
    fn read_rays(&self, gpu: &Gpu) -> Result<u64, RenderError> {
        let words: Vec<u32> = self.counters_readback.read_from(gpu, &self.counters)?;
        Ok(words[0] as u64)
    }

    /// The radiance sum (w: samples) that the bench's wavefront tracer also accumulates into.
    pub fn radiance_sum_buffer(&self) -> &wgpu::Buffer {
        &self.radiance_sum
    }

    /// The ray counter ([0]: rays traced since the last clear).
    pub fn counters_buffer(&self) -> &wgpu::Buffer {
        &self.counters
    }

    /// The radiance sum as per-pixel means.
    pub fn read_radiance_mean(&self, gpu: &Gpu) -> Result<Vec<[f32; 4]>, RenderError> {
        self.read_radiance(gpu)
    }

    fn read_radiance(&self, gpu: &Gpu) -> Result<Vec<[f32; 4]>, RenderError> {
        let sums: Vec<[f32; 4]> = self.radiance_readback.read_from(gpu, &self.radiance_sum)?;
        // w holds the sample count: the mean is sum / count.
        Ok(sums
            .into_iter()
            .map(|s| {
                if s[3] > 0.0 {
                    [s[0] / s[3], s[1] / s[3], s[2] / s[3], 1.0]
                } else {
                    [0.0, 0.0, 0.0, 1.0]
                }
            })
            .collect())
    }

    fn read_gbuffer(&self, gpu: &Gpu) -> Result<GBuffer, RenderError> {
        let texels: Vec<GBufferTexel> = self.gbuffer_readback.read_from(gpu, &self.gbuffer)?;
        let mut g = GBuffer::default();
        for t in texels {
            g.depth.push(if t.instance == NO_HIT { f32::INFINITY } else { t.depth });
            g.normal.push(t.normal);
            g.albedo.push(t.albedo);
            g.motion.push(t.motion);
            g.instance_id.push(t.instance);
            g.primitive_id.push(t.primitive);
        }
        Ok(g)
    }
}

/// The path tracer's own @group(2), declared into its WGSL: the radiance sum (w: samples), the
/// G-buffer, per-(chunk, pixel) partial sums of one dispatch (`accumulate_main` adds them up in
/// chunk order), and [0] = rays traced by this frame's passes.
const OWN_GROUP: [BufferBinding; 4] = [
    BufferBinding::read_write("radiance_sum", "array<vec4f>"),
    BufferBinding::read_write("gbuffer", "array<GBufferTexel>"),
    BufferBinding::read_write("sample_partials", "array<vec4f>"),
    BufferBinding::read_write("pt_counters", "array<atomic<u32>>"),
];
