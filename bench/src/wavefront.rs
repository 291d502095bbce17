//! The path tracer's references traced as a wavefront (Laine, Karras & Aila 2013): paths live in
//! a queue in GPU memory, and each bounce is three kernels over the live paths (extend, shade,
//! shadow), with the survivors compacted into the other queue and the next bounce dispatched
//! indirectly over them. Each sample's value is the megakernel's (same random numbers, same
//! order of sums); bench/shaders/wavefront.wgsl says how.
//!
//! It renders into a [`PathTracer`]'s radiance sum, so `PathTracer::read_radiance` reads it, with
//! its own frame parameters.

use render::compute::{self, BufferBinding};
use render::error::RenderError;
use render::frame_bindings::FrameBindings;
use render::gpu::Gpu;
use render::pass_library::LibraryPipeline;
use render::path_tracer::{PathTracer, SAMPLES_PER_THREAD};
use render::readback::read_buffer;
use render::scene_gpu::SceneGpu;
use render::shader::{Module, Program};

/// Invocations per workgroup of the queue kernels.
const WF_GROUP: u32 = 64;

/// Paths in flight in one wave: what bounds its memory.
pub const WAVE_PATHS: u64 = 1 << 18;

/// Bounces recorded per submission between two reads of the live count.
const BOUNCES_PER_SUBMISSION: u32 = 8;

/// wf_control: live, next, parity, capacity, then the indirect dispatch (x, y, z).
const CONTROL_WORDS: u64 = 8;
const CTRL_ARGS: u64 = 4;

/// vec4s per path of a wave: two queues of 4, the hit (2), the sample's radiance (1), the shadow
/// group (1); plus 3 per light sample.
const VEC4S_PER_PATH: u64 = 4 + 4 + 2 + 1 + 1;
const VEC4S_PER_LIGHT_SAMPLE: u64 = 3;

const OWN_GROUP: [BufferBinding; 4] = [
    BufferBinding::read_write("radiance_sum", "array<vec4f>"),
    BufferBinding::read_write("pt_counters", "array<atomic<u32>>"),
    BufferBinding::read_write("wf_state", "array<vec4f>"),
    BufferBinding::read_write("wf_control", "array<atomic<u32>>"),
];

pub struct Wavefront {
    frame: FrameBindings,
    layout: wgpu::BindGroupLayout,
    generate: LibraryPipeline,
    extend: LibraryPipeline,
    shade: LibraryPipeline,
    shadow: LibraryPipeline,
    advance: LibraryPipeline,
    reduce: LibraryPipeline,
    state: wgpu::Buffer,
    control: wgpu::Buffer,
    /// The next bounce's indirect dispatch, copied from wf_control.
    args: wgpu::Buffer,
    control_readback: wgpu::Buffer,
    /// Paths of one wave (a whole number of sample chunks per pixel).
    capacity: u64,
    light_samples: u64,
}

impl Wavefront {
    /// Waves of about [`WAVE_PATHS`] paths.
    pub fn new(gpu: &Gpu, scene: &SceneGpu) -> Result<Self, RenderError> {
        Self::with_wave_paths(gpu, scene, WAVE_PATHS)
    }

    /// Waves of whole chunks of [`SAMPLES_PER_THREAD`] samples per pixel, as many as fit in
    /// `wave_paths` paths (at least one chunk) and in the adapter's largest storage binding.
    pub fn with_wave_paths(
        gpu: &Gpu,
        scene: &SceneGpu,
        wave_paths: u64,
    ) -> Result<Self, RenderError> {
        let (layout, [generate, extend, shade, shadow, advance, reduce]) = scene.library_pass(
            gpu,
            "wavefront.wgsl",
            Self::program(),
            &OWN_GROUP,
            ["wf_generate", "wf_extend", "wf_shade", "wf_shadow", "wf_advance", "wf_reduce"],
        )?;
        let settings = scene.settings();
        let pixels = settings.width as u64 * settings.height as u64;
        let light_samples = Self::light_samples(scene);
        let per_path = 16 * (VEC4S_PER_PATH + VEC4S_PER_LIGHT_SAMPLE * light_samples);
        let max_paths =
            gpu.limits.max_storage_buffer_binding_size.min(gpu.limits.max_buffer_size) / per_path;
        let chunk_paths = pixels * SAMPLES_PER_THREAD as u64;
        let chunks = (wave_paths.min(max_paths) / chunk_paths).max(1);
        let capacity = chunks * chunk_paths;
        if capacity > max_paths
            || capacity.div_ceil(WF_GROUP as u64)
                > gpu.limits.max_compute_workgroups_per_dimension as u64
        {
            return Err(RenderError::Settings(format!(
                "a wavefront of {pixels} pixels x {SAMPLES_PER_THREAD} samples does not fit this adapter"
            )));
        }
        let size = capacity * per_path;
        gpu.check_buffer_size("wavefront state", size)?;
        let state = gpu.device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("wavefront state"),
            size,
            usage: wgpu::BufferUsages::STORAGE,
            mapped_at_creation: false,
        });
        let control = gpu.device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("wavefront control"),
            size: CONTROL_WORDS * 4,
            usage: wgpu::BufferUsages::STORAGE
                | wgpu::BufferUsages::COPY_DST
                | wgpu::BufferUsages::COPY_SRC,
            mapped_at_creation: false,
        });
        let control_readback = gpu.device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("wavefront control readback"),
            size: CONTROL_WORDS * 4,
            usage: wgpu::BufferUsages::MAP_READ | wgpu::BufferUsages::COPY_DST,
            mapped_at_creation: false,
        });
        let args = gpu.device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("wavefront dispatch"),
            size: 12,
            usage: wgpu::BufferUsages::INDIRECT | wgpu::BufferUsages::COPY_DST,
            mapped_at_creation: false,
        });
        Ok(Self {
            frame: FrameBindings::new(gpu, scene),
            layout,
            generate,
            extend,
            shade,
            shadow,
            advance,
            reduce,
            state,
            control,
            args,
            control_readback,
            capacity,
            light_samples,
        })
    }

    /// Light samples per shading point, as wavefront.wgsl's `light_samples` counts them.
    fn light_samples(scene: &SceneGpu) -> u64 {
        let features = scene.library().features();
        scene.analytic_lights() as u64 * features.analytic_lights as u64
            + features.emitters as u64
            + features.environment as u64
    }

    fn program() -> &'static Program {
        static PROGRAM: std::sync::OnceLock<Program> = std::sync::OnceLock::new();
        PROGRAM.get_or_init(|| {
            let types = Module::generated(
                "package::bench::wavefront_types",
                &[&format!("const SAMPLES_PER_THREAD: u32 = {SAMPLES_PER_THREAD}u;\nconst WF_GROUP: u32 = {WF_GROUP}u;")],
            );
            let bindings = compute::group_module("package::bench::wavefront_bindings", 2, &OWN_GROUP, &[&types]);
            render::pass_library::PassLibrary::program([types, bindings], [render::wgsl_file!("wavefront.wgsl")])
        })
    }

    /// Samples per pixel of one wave.
    pub fn samples_per_wave(&self, scene: &SceneGpu) -> u32 {
        let settings = scene.settings();
        (self.capacity / (settings.width as u64 * settings.height as u64)) as u32
    }

    /// [`PathTracer::render_reference`] as a wavefront: `spp` samples per pixel in waves of
    /// [`Self::samples_per_wave`], into `tracer`'s radiance sum.
    pub fn render_reference(
        &self,
        gpu: &Gpu,
        scene: &SceneGpu,
        tracer: &PathTracer,
        spp: u32,
        seed: u64,
        frame: u32,
    ) -> Result<Vec<[f32; 4]>, RenderError> {
        self.trace(gpu, scene, tracer, spp, seed, frame, None)
    }

    /// [`Self::render_reference`] with each kernel submitted alone and waited for, its wall time
    /// added to `times`: slower, for seeing where a wavefront's time goes.
    #[allow(clippy::too_many_arguments)]
    pub fn render_reference_per_kernel(
        &self,
        gpu: &Gpu,
        scene: &SceneGpu,
        tracer: &PathTracer,
        spp: u32,
        seed: u64,
        frame: u32,
        times: &mut KernelTimes,
    ) -> Result<Vec<[f32; 4]>, RenderError> {
        self.trace(gpu, scene, tracer, spp, seed, frame, Some(times))
    }

    #[allow(clippy::too_many_arguments)]
    fn trace(
        &self,
        gpu: &Gpu,
        scene: &SceneGpu,
        tracer: &PathTracer,
        spp: u32,
        seed: u64,
        frame: u32,
        mut times: Option<&mut KernelTimes>,
    ) -> Result<Vec<[f32; 4]>, RenderError> {
        if spp == 0 {
            return Err(RenderError::Settings("reference spp must be at least 1".into()));
        }
        if Self::light_samples(scene) > self.light_samples {
            return Err(RenderError::Settings(format!(
                "the scene has {} light samples per shading point, the wavefront was sized for {}: build it again",
                Self::light_samples(scene),
                self.light_samples
            )));
        }
        let settings = scene.settings();
        let pixels = settings.width as u64 * settings.height as u64;
        let bind_group = compute::buffer_group(
            gpu,
            "wavefront",
            &self.layout,
            &[tracer.radiance_sum_buffer(), tracer.counters_buffer(), &self.state, &self.control],
        );
        let per_wave = self.samples_per_wave(scene);
        let new_encoder = || {
            gpu.device.create_command_encoder(&wgpu::CommandEncoderDescriptor {
                label: Some("wavefront"),
            })
        };
        // One kernel in its own compute pass; with `times`, submitted and waited for alone.
        let run = |encoder: &mut wgpu::CommandEncoder,
                   kernel: Kernel,
                   dispatch: Dispatch,
                   times: &mut Option<&mut KernelTimes>| {
            {
                let mut pass = encoder.begin_compute_pass(&wgpu::ComputePassDescriptor {
                    label: Some(kernel.name()),
                    timestamp_writes: None,
                });
                self.frame.bind(gpu, scene, &mut pass);
                pass.set_bind_group(2, &bind_group, &[]);
                pass.set_pipeline(&self.pipeline(kernel).get());
                match dispatch {
                    Dispatch::Direct(x, y) => pass.dispatch_workgroups(x, y, 1),
                    Dispatch::Indirect => pass.dispatch_workgroups_indirect(&self.args, 0),
                }
            }
            if let Some(times) = times {
                let start = std::time::Instant::now();
                gpu.queue.submit([std::mem::replace(encoder, new_encoder()).finish()]);
                let _ = gpu.device.poll(wgpu::PollType::wait_indefinitely());
                times.seconds[kernel as usize] += start.elapsed().as_secs_f64();
            }
        };
        let mut done = 0;
        while done < spp {
            let batch = per_wave.min(spp - done);
            self.frame.write(gpu, scene, batch, done, seed, frame, done > 0);
            let paths = pixels as u32 * batch;
            let groups = paths.div_ceil(WF_GROUP);
            let control: [u32; CONTROL_WORDS as usize] =
                [paths, 0, 0, self.capacity as u32, groups, 1, 1, 0];
            gpu.queue.write_buffer(&self.control, 0, bytemuck::cast_slice(&control));
            let mut encoder = new_encoder();
            run(&mut encoder, Kernel::Generate, Dispatch::Direct(groups, 1), &mut times);
            let mut bounces = 0u32;
            loop {
                for _ in 0..BOUNCES_PER_SUBMISSION {
                    // The indirect arguments are copied out of wf_control: a buffer bound for
                    // storage cannot also be a dispatch's indirect buffer.
                    encoder.copy_buffer_to_buffer(&self.control, CTRL_ARGS * 4, &self.args, 0, 12);
                    for kernel in [Kernel::Extend, Kernel::Shade, Kernel::Shadow] {
                        run(&mut encoder, kernel, Dispatch::Indirect, &mut times);
                    }
                    run(&mut encoder, Kernel::Advance, Dispatch::Direct(1, 1), &mut times);
                }
                encoder.copy_buffer_to_buffer(
                    &self.control,
                    0,
                    &self.control_readback,
                    0,
                    CONTROL_WORDS * 4,
                );
                gpu.queue.submit([std::mem::replace(&mut encoder, new_encoder()).finish()]);
                let words: Vec<u32> =
                    read_buffer(gpu, &self.control_readback).map_err(|reason| {
                        RenderError::Readback { what: "wavefront control".into(), reason }
                    })?;
                bounces += BOUNCES_PER_SUBMISSION;
                if words[0] == 0 || bounces > settings.max_depth + 1 {
                    break;
                }
            }
            run(
                &mut encoder,
                Kernel::Reduce,
                Dispatch::Direct(settings.width.div_ceil(8), settings.height.div_ceil(8)),
                &mut times,
            );
            gpu.queue.submit([encoder.finish()]);
            done += batch;
        }
        tracer.read_radiance_mean(gpu)
    }

    fn pipeline(&self, kernel: Kernel) -> &LibraryPipeline {
        match kernel {
            Kernel::Generate => &self.generate,
            Kernel::Extend => &self.extend,
            Kernel::Shade => &self.shade,
            Kernel::Shadow => &self.shadow,
            Kernel::Advance => &self.advance,
            Kernel::Reduce => &self.reduce,
        }
    }
}

/// The wavefront's kernels, in the order of [`KernelTimes::seconds`].
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Kernel {
    Generate,
    Extend,
    Shade,
    Shadow,
    Advance,
    Reduce,
}

impl Kernel {
    pub const ALL: [Kernel; 6] = [
        Kernel::Generate,
        Kernel::Extend,
        Kernel::Shade,
        Kernel::Shadow,
        Kernel::Advance,
        Kernel::Reduce,
    ];

    pub fn name(self) -> &'static str {
        match self {
            Kernel::Generate => "generate",
            Kernel::Extend => "extend",
            Kernel::Shade => "shade",
            Kernel::Shadow => "shadow",
            Kernel::Advance => "advance",
            Kernel::Reduce => "reduce",
        }
    }
}

enum Dispatch {
    Direct(u32, u32),
    Indirect,
}

/// Wall seconds per kernel, indexed by [`Kernel`].
#[derive(Clone, Debug, Default)]
pub struct KernelTimes {
    pub seconds: [f64; 6],
}
