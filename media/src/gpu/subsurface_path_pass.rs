//! The random-walk ground truth of subsurface materials on the GPU
//! (media/shaders/media_subsurface_path.wgsl): the path tracer with every subsurface material a
//! homogeneous medium inside its mesh (scene::SubsurfaceMedium's coefficients, an index-matched
//! boundary, isotropic phase). Groups: 0 and 1 the scene (with the caller's frame parameters)
//! and geometry, 2 this pass's parameters, the coefficients per material and the per-sample
//! radiance. Scenes without subsurface materials render as the path tracer renders them.

use render::compute::{BufferBinding, binding_layout, buffer_group, pipelines};
use render::frame_bindings::FrameBindings;
use render::gpu::Gpu;
use render::gpu_struct::GpuStruct;
use render::pass_library::PassLibrary;
use render::scene_features::SceneFeatures;
use render::scene_gpu::SceneGpu;
use render::shader::{Module, Program};
use render::timing::PassTimer;
use scene::{Material, SubsurfaceMedium};

use super::VolumeImage;
use super::specialised_pipeline::SpecialisedPipeline;

render::gpu_struct! {
    pub struct SubsurfacePathParams {
        /// Samples per pixel in this dispatch, from `first_sample` on.
        pub spp: u32 => "u32",
        pub first_sample: u32 => "u32",
        /// Materials in the coefficient table.
        pub materials: u32 => "u32",
        /// Scattering events after which a walk is dropped.
        pub max_events: u32 => "u32",
    }
}

const BINDINGS: [BufferBinding; 3] = [
    BufferBinding::read("sp", "SubsurfacePathParams"),
    // per material m: (σ_t, 1 if subsurface) at 2m, (α, 0) at 2m + 1
    BufferBinding::read("coefficients", "array<vec4f>"),
    BufferBinding::read_write("samples", "array<vec4f>"),
];

/// The pass's name in timings.
pub const SUBSURFACE_PATH_PASS: &str = "subsurface_path";

/// Scattering events per walk: short invocations (llvmpipe's loop limit). With α = 0.99 a walk
/// survives 256 events with probability 0.99²⁵⁶ = 0.08 before it has left, and most of those
/// have left by then; the GPU test bounds what is lost.
pub const MAX_EVENTS: u32 = 256;

/// The coefficient table of `materials`: each subsurface material's medium, zero elsewhere; or
/// the first material that has none (its index and why).
pub fn coefficient_table(materials: &[Material]) -> Result<Vec<[f32; 4]>, String> {
    let mut table = Vec::with_capacity(2 * materials.len().max(1));
    for (i, m) in materials.iter().enumerate() {
        match m.subsurface {
            Some(s) => {
                let medium = SubsurfaceMedium::from_albedo(m.base_color, s.dmfp)
                    .map_err(|e| format!("material {i}: {e}"))?;
                table.push(medium.sigma_t.extend(1.0).into());
                table.push(medium.albedo.extend(0.0).into());
            }
            None => table.extend([[0.0; 4]; 2]),
        }
    }
    if table.is_empty() {
        table.extend([[0.0; 4]; 2]);
    }
    Ok(table)
}

pub struct SubsurfacePathPass {
    layout: wgpu::BindGroupLayout,
    pipeline: SpecialisedPipeline,
    timer: PassTimer,
}

impl SubsurfacePathPass {
    pub fn program() -> Program {
        let types = Module::generated(
            "package::media::subsurface_path_types",
            &[SubsurfacePathParams::WGSL],
        );
        let bindings = render::compute::group_module(
            "package::media::subsurface_path_bindings",
            2,
            &BINDINGS,
            &[&types],
        );
        PassLibrary::program(
            [types, bindings, render::wgsl_file!("media_free_flight.wgsl")],
            [render::wgsl_file!("media_subsurface_path.wgsl")],
        )
    }

    /// Every WGSL source of the pass: part of the key of cached references.
    pub fn shader_source() -> &'static str {
        static SOURCE: std::sync::OnceLock<String> = std::sync::OnceLock::new();
        SOURCE.get_or_init(|| Self::program().fingerprint())
    }

    pub fn new(gpu: &Gpu, scene: &SceneGpu) -> Result<Self, String> {
        let layout = binding_layout(gpu, "subsurface path", &BINDINGS);
        let pipeline =
            SpecialisedPipeline::new(scene.features(), |f| Self::compile(gpu, scene, &layout, f))?;
        Ok(Self { layout, pipeline, timer: PassTimer::new(gpu, &[SUBSURFACE_PATH_PASS]) })
    }

    fn compile(
        gpu: &Gpu,
        scene: &SceneGpu,
        layout: &wgpu::BindGroupLayout,
        features: SceneFeatures,
    ) -> Result<wgpu::ComputePipeline, String> {
        let program = Self::program().replacing(&features.module());
        let [pipeline] = pipelines(
            gpu,
            "subsurface path",
            &program,
            &[scene.layout(), scene.geometry().bind_group_layout(), layout],
            ["subsurface_path"],
        )
        .map_err(|e| e.to_string())?;
        Ok(pipeline)
    }

    /// `spp` paths per pixel of the current scene and camera (seed and frame as the path
    /// tracer's); `materials` the scene's (their subsurface parameters give the media).
    #[allow(clippy::too_many_arguments)]
    pub fn render(
        &self,
        gpu: &Gpu,
        scene: &SceneGpu,
        bindings: &FrameBindings,
        materials: &[Material],
        spp: u32,
        seed: u64,
        frame: u32,
    ) -> Result<VolumeImage, String> {
        gpu.check_loop_iterations(SUBSURFACE_PATH_PASS, u64::from(MAX_EVENTS) * 4)
            .map_err(|e| e.to_string())?;
        let table = coefficient_table(materials)?;
        let pipeline =
            self.pipeline.get(scene.features(), |f| Self::compile(gpu, scene, &self.layout, f))?;
        let coefficients = gpu.buffer_init(
            "subsurface coefficients",
            bytemuck::cast_slice(&table),
            wgpu::BufferUsages::STORAGE,
        );
        let batched = super::volume_path_pass::Batched {
            gpu,
            scene,
            bindings,
            timer: &self.timer,
            pass: SUBSURFACE_PATH_PASS,
            label: "subsurface path",
            pipeline: &pipeline,
            medium: None,
        };
        batched.render(spp, seed, frame, |first, n, samples| {
            let params = SubsurfacePathParams {
                spp: n,
                first_sample: first,
                materials: materials.len() as u32,
                max_events: MAX_EVENTS,
            };
            let params = gpu.buffer_init(
                "subsurface path params",
                bytemuck::bytes_of(&params),
                wgpu::BufferUsages::STORAGE,
            );
            buffer_group(gpu, "subsurface path", &self.layout, &[&params, &coefficients, samples])
        })
    }
}
