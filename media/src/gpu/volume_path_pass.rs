//! Volumetric path tracing on the scene on the GPU (media/shaders/media_path.wgsl): unbiased
//! references of a scene with one or several media (their extinctions add). Groups: 0 and 1 the
//! scene (with the caller's frame parameters) and geometry, 2 this pass's parameters, the media's
//! optics and per-sample radiance, 3 the media (`GpuMedium`). A scene without media never builds
//! this pass: the path tracer and its shaders are unchanged.

use glam::Vec3;
use render::compute::{BufferBinding, binding_layout, buffer_group, pipelines};
use render::error::RenderError;
use render::frame_bindings::FrameBindings;
use render::gpu::Gpu;
use render::gpu_struct::GpuStruct;
use render::pass_library::PassLibrary;
use render::readback::Staging;
use render::scene_features::SceneFeatures;
use render::scene_gpu::SceneGpu;
use render::shader::{Module, Program};
use render::timing::{PassTimer, PassTiming, merge};
use serde::{Deserialize, Serialize};

use super::medium::GpuMedium;
use super::specialised_pipeline::SpecialisedPipeline;

/// What a medium does to light beside extinction: single-scattering albedo σ_s/σ_t per channel,
/// and emitted radiance per unit extinction (the source term σ_t(x) ε; zero: none).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct MediumOptics {
    pub albedo: Vec3,
    pub emission: Vec3,
}

impl MediumOptics {
    /// A medium that scatters with `albedo` and emits nothing.
    pub fn scattering(albedo: Vec3) -> Self {
        Self { albedo, emission: Vec3::ZERO }
    }
}

/// The MIS weight of free-flight sampling against equiangular sampling of positional lights
/// (Sec. 5.2); `None`: free-flight (delta tracking) only.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash, Serialize, Deserialize)]
pub enum MisWeight {
    #[default]
    None,
    /// g(X0) of one optical-depth estimate (m = 1, the paper's Fig. 12d).
    Naive,
    /// Re g(X̄ + iS) (Eq. 12, Appendix F).
    Jackknife,
    /// Miller et al. 2019's ratio-tracking weight.
    Miller,
}

/// How the equiangular sample is weighted: Eq. 9 (unbiased, a separate ratio-tracking T̃(t0)) or
/// Eq. 10 (the weight estimate carries the transmittance; slightly biased).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash, Serialize, Deserialize)]
pub enum Combination {
    #[default]
    Eq9,
    Eq10,
}

/// The transmittance estimate of shadow rays.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash, Serialize, Deserialize)]
pub enum ShadowTransmittance {
    #[default]
    RatioTracking,
    TrackLength,
    /// Eq. 3 from `shadow_estimates` (m) optical-depth estimates of `shadow_samples` (N) samples
    /// each, summed over the media (the paper's Figs. 1 and 12: m = 2, N = 10).
    Jackknife,
}

/// The unbiased transmittance T̃(t0) of Eq. 9's equiangular sample: ratio tracking (the
/// default), or regular tracking through the voxels, exact for the nearest-neighbour grids (an
/// experiment: whether T̃'s noise is what makes Eq. 9 worse than free flight here).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash, Serialize, Deserialize)]
pub enum Eq9Transmittance {
    #[default]
    RatioTracking,
    Exact,
}

#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct VolumePathSettings {
    pub mis: MisWeight,
    pub combination: Combination,
    pub shadow: ShadowTransmittance,
    /// Samples N of each optical-depth estimate of a weight (the naive reads one, the jackknife
    /// two).
    pub samples: u32,
    /// N of each optical-depth estimate of a jackknife shadow ray (the paper's 10).
    pub shadow_samples: u32,
    /// m, the optical-depth estimates of a jackknife shadow ray (2 to 9; the paper's 2).
    pub shadow_estimates: u32,
    /// When set, a jackknife shadow ray's N is tied to its importance (Fig. 8d): N =
    /// ceil(F / step) in [1, 64], F Alg. 2's integral of importance; `shadow_samples` unused.
    pub shadow_step: Option<f32>,
    pub eq9_transmittance: Eq9Transmittance,
}

impl Default for VolumePathSettings {
    fn default() -> Self {
        Self {
            mis: MisWeight::None,
            combination: Combination::Eq9,
            shadow: ShadowTransmittance::RatioTracking,
            samples: 4,
            shadow_samples: 10,
            shadow_estimates: 2,
            shadow_step: None,
            eq9_transmittance: Eq9Transmittance::RatioTracking,
        }
    }
}

impl VolumePathSettings {
    /// What the settings must satisfy: N ≥ 1, 2 ≤ m ≤ 9, a positive step.
    pub fn problem(&self) -> Option<String> {
        if self.samples == 0 {
            return Some("samples 0; expected at least 1 sample per optical-depth estimate".into());
        }
        if self.shadow_samples == 0 {
            return Some(
                "shadow_samples 0; expected at least 1 sample per optical-depth estimate (N)"
                    .into(),
            );
        }
        if !(2..=crate::optical_depth::MAX_ESTIMATES as u32).contains(&self.shadow_estimates) {
            return Some(format!(
                "shadow_estimates {}; expected m from 2 to {} (Eq. 3 needs a sample variance)",
                self.shadow_estimates,
                crate::optical_depth::MAX_ESTIMATES
            ));
        }
        if let Some(step) = self.shadow_step
            && !(step > 0.0 && step.is_finite())
        {
            return Some(format!(
                "shadow_step {step}; expected a positive CDF step size F_Δ (optical depth)"
            ));
        }
        None
    }
}

render::gpu_struct! {
    pub struct VolumePathParams {
        pub mis: u32 => "u32",
        pub eq10: u32 => "u32",
        pub shadow: u32 => "u32",
        pub samples: u32 => "u32",
        /// Samples per pixel in this dispatch, from `first_sample` on.
        pub spp: u32 => "u32",
        pub first_sample: u32 => "u32",
        pub shadow_samples: u32 => "u32",
        pub shadow_estimates: u32 => "u32",
        /// F_Δ of an importance-tied N; 0: N = shadow_samples.
        pub shadow_step: f32 => "f32",
        pub eq9_exact: u32 => "u32",
        pub _pad0: u32 => "u32",
        pub _pad1: u32 => "u32",
    }
}

const BINDINGS: [BufferBinding; 3] = [
    BufferBinding::read("vp", "VolumePathParams"),
    // per medium of the GpuMedium: albedo at 2i, emission (radiance per unit extinction) at 2i + 1
    // 2 × MAX_MEDIA (asserted in medium.rs): albedo and emission per medium.
    BufferBinding::read("optics", "array<vec4f, 16>"),
    BufferBinding::read_write("samples", "array<vec4f>"),
];

/// Paths per dispatch: short invocations (llvmpipe's loop limit, GPU watchdogs) and a bounded
/// sample buffer.
const PATHS_PER_DISPATCH: u32 = 1 << 18;

/// Per pixel: the mean radiance and the variance of that mean's luminance (from the samples).
pub struct VolumeImage {
    pub width: u32,
    pub height: u32,
    pub mean: Vec<[f32; 3]>,
    pub var_of_mean: Vec<f64>,
    /// GPU (or wall) time of pass `volume_path`, all batches.
    pub timings: Vec<PassTiming>,
    /// Paths traced.
    pub paths: u64,
}

/// The pass's name in timings.
pub const VOLUME_PATH_PASS: &str = "volume_path";

pub struct VolumePathPass {
    layout: wgpu::BindGroupLayout,
    /// Compiled for the scene's features (this pass binds a fourth group, which the library's
    /// passes do not, so it holds its own).
    pipeline: SpecialisedPipeline,
    timer: PassTimer,
}

impl VolumePathPass {
    /// The pass's program: the path tracer's library, the media library with the medium as
    /// @group(3), its own @group(2), media_path.wgsl.
    pub fn program() -> Program {
        let types =
            Module::generated("package::media::volume_path_types", &[VolumePathParams::WGSL]);
        let bindings = render::compute::group_module(
            "package::media::volume_path_bindings",
            2,
            &BINDINGS,
            &[&types],
        );
        let mut own = super::shaders::modules_at(3);
        own.extend([types, bindings, render::wgsl_file!("media_path.wgsl")]);
        PassLibrary::program(own, [render::wgsl_file!("media_volume_path.wgsl")])
    }

    /// Every WGSL source of the pass: part of the key of cached references.
    pub fn shader_source() -> &'static str {
        static SOURCE: std::sync::OnceLock<String> = std::sync::OnceLock::new();
        SOURCE.get_or_init(|| Self::program().fingerprint())
    }

    pub fn new(gpu: &Gpu, scene: &SceneGpu, medium: &GpuMedium) -> Result<Self, RenderError> {
        let layout = binding_layout(gpu, "media volume path", &BINDINGS);
        let pipeline = SpecialisedPipeline::new(scene.features(), |f| {
            Self::compile(gpu, scene, &layout, medium, f)
        })?;
        Ok(Self { layout, pipeline, timer: PassTimer::new(gpu, &[VOLUME_PATH_PASS]) })
    }

    fn compile(
        gpu: &Gpu,
        scene: &SceneGpu,
        layout: &wgpu::BindGroupLayout,
        medium: &GpuMedium,
        features: SceneFeatures,
    ) -> Result<wgpu::ComputePipeline, RenderError> {
        let program = Self::program().replacing(&features.module());
        let [pipeline] = pipelines(
            gpu,
            "media volume path",
            &program,
            &[scene.layout(), scene.geometry().bind_group_layout(), layout, &medium.layout],
            ["volume_path"],
        )?;
        Ok(pipeline)
    }

    /// The pipeline for the scene as it is now.
    fn pipeline(
        &self,
        gpu: &Gpu,
        scene: &SceneGpu,
        medium: &GpuMedium,
    ) -> Result<wgpu::ComputePipeline, RenderError> {
        self.pipeline.get(scene.features(), |f| Self::compile(gpu, scene, &self.layout, medium, f))
    }

    /// The scene features the pipeline was last compiled for.
    pub fn features(&self) -> SceneFeatures {
        self.pipeline.features()
    }

    /// `spp` paths per pixel of the current scene and camera (seed and frame as the path
    /// tracer's), in the media of `medium` with the given albedo and emission, one per medium.
    /// `bindings` holds the caller's frame parameters (the references', a method's).
    #[allow(clippy::too_many_arguments)]
    pub fn render(
        &self,
        gpu: &Gpu,
        scene: &SceneGpu,
        bindings: &FrameBindings,
        medium: &GpuMedium,
        optics: &[MediumOptics],
        settings: &VolumePathSettings,
        spp: u32,
        seed: u64,
        frame: u32,
    ) -> Result<VolumeImage, String> {
        if let Some(problem) = settings.problem() {
            return Err(problem);
        }
        if optics.len() != medium.count {
            return Err(format!(
                "{} media bound but {} optics given; expected one albedo and emission per medium",
                medium.count,
                optics.len()
            ));
        }
        let mut packed = [[0f32; 4]; 2 * super::medium::MAX_MEDIA];
        for (i, o) in optics.iter().enumerate() {
            packed[2 * i] = o.albedo.extend(0.0).into();
            packed[2 * i + 1] = o.emission.extend(0.0).into();
        }
        let pipeline = self.pipeline(gpu, scene, medium).map_err(|e| e.to_string())?;
        let batched = Batched {
            gpu,
            scene,
            bindings,
            timer: &self.timer,
            pass: VOLUME_PATH_PASS,
            label: "volume path",
            pipeline: &pipeline,
            medium: Some(&medium.group),
        };
        batched.render(spp, seed, frame, |first, n, samples| {
            let params = VolumePathParams {
                mis: settings.mis as u32,
                eq10: u32::from(settings.combination == Combination::Eq10),
                shadow: settings.shadow as u32,
                samples: settings.samples,
                spp: n,
                first_sample: first,
                shadow_samples: settings.shadow_samples,
                shadow_estimates: settings.shadow_estimates,
                shadow_step: settings.shadow_step.unwrap_or(0.0),
                eq9_exact: u32::from(settings.eq9_transmittance == Eq9Transmittance::Exact),
                _pad0: 0,
                _pad1: 0,
            };
            let params = gpu.buffer_init(
                "volume path params",
                bytemuck::bytes_of(&params),
                wgpu::BufferUsages::STORAGE,
            );
            let optics = gpu.buffer_init(
                "volume path optics",
                bytemuck::cast_slice(&packed),
                wgpu::BufferUsages::STORAGE,
            );
            buffer_group(gpu, "media volume path", &self.layout, &[&params, &optics, samples])
        })
    }
}

/// A pass that writes one radiance sample per path (group 2 its own, holding the samples buffer;
/// group 3 the media, where it binds them), rendered in batches of at most `PATHS_PER_DISPATCH`
/// paths and summed per pixel: the volumetric path tracer and the subsurface random walk.
pub(super) struct Batched<'a> {
    pub gpu: &'a Gpu,
    pub scene: &'a SceneGpu,
    pub bindings: &'a FrameBindings,
    pub timer: &'a PassTimer,
    /// The pass's name in timings.
    pub pass: &'static str,
    /// Prefix of the buffers' labels.
    pub label: &'static str,
    pub pipeline: &'a wgpu::ComputePipeline,
    pub medium: Option<&'a wgpu::BindGroup>,
}

impl Batched<'_> {
    /// `spp` samples per pixel; `group(first, n, samples)` gives the batch's group 2 for samples
    /// `first .. first + n` of every pixel, written into `samples`.
    pub(super) fn render(
        &self,
        spp: u32,
        seed: u64,
        frame: u32,
        mut group: impl FnMut(u32, u32, &wgpu::Buffer) -> wgpu::BindGroup,
    ) -> Result<VolumeImage, String> {
        let (width, height) = {
            let s = self.scene.settings();
            (s.width, s.height)
        };
        let pixels = width * height;
        let batch = (PATHS_PER_DISPATCH / pixels).clamp(1, spp.max(1));
        let size = u64::from(pixels * batch) * 16;
        let label = format!("{} samples", self.label);
        let samples = self.gpu.device.create_buffer(&wgpu::BufferDescriptor {
            label: Some(&label),
            size,
            usage: wgpu::BufferUsages::STORAGE | wgpu::BufferUsages::COPY_SRC,
            mapped_at_creation: false,
        });
        let staging = Staging::new(self.gpu, &label, size);
        let mut image = Accumulator::new(pixels as usize);
        let mut timings = Vec::new();
        let mut first = 0;
        while first < spp {
            let n = batch.min(spp - first);
            self.bindings.prepare(self.gpu, self.scene, spp, 0, seed, frame);
            let group = group(first, n, &samples);
            let mut timed = self.timer.begin(self.gpu, self.pass);
            timed
                .pass(0, |pass| {
                    pass.set_pipeline(self.pipeline);
                    self.bindings.bind(self.gpu, self.scene, pass);
                    pass.set_bind_group(2, &group, &[]);
                    if let Some(medium) = self.medium {
                        pass.set_bind_group(3, medium, &[]);
                    }
                    let groups = (pixels * n).div_ceil(64);
                    pass.dispatch_workgroups(groups.min(65535), groups.div_ceil(65535), 1);
                })
                .map_err(|e| e.to_string())?;
            staging.record(timed.encoder(), &samples, 0);
            merge(&mut timings, timed.submit().map_err(|e| e.to_string())?);
            let raw: Vec<[f32; 4]> = staging.read(self.gpu).map_err(|e| e.to_string())?;
            image.add(&raw[..(pixels * n) as usize], n as usize);
            first += n;
        }
        Ok(image.finish(width, height, spp, timings))
    }
}

/// Per pixel, sums of the samples' radiance and of their luminance and its square, batch by
/// batch (samples of pixel p at p·n .. (p + 1)·n of a batch of n per pixel).
struct Accumulator {
    sum: Vec<[f64; 3]>,
    lum: Vec<(f64, f64)>,
}

impl Accumulator {
    fn new(pixels: usize) -> Self {
        Self { sum: vec![[0f64; 3]; pixels], lum: vec![(0f64, 0f64); pixels] }
    }

    fn add(&mut self, samples: &[[f32; 4]], n: usize) {
        for (i, v) in samples.iter().enumerate() {
            let p = i / n;
            for (sum, x) in self.sum[p].iter_mut().zip(v) {
                *sum += f64::from(*x);
            }
            let l = 0.2126 * f64::from(v[0]) + 0.7152 * f64::from(v[1]) + 0.0722 * f64::from(v[2]);
            self.lum[p].0 += l;
            self.lum[p].1 += l * l;
        }
    }

    /// The mean and the variance of the mean's luminance over `spp` samples per pixel.
    fn finish(self, width: u32, height: u32, spp: u32, timings: Vec<PassTiming>) -> VolumeImage {
        let k = f64::from(spp);
        let mean = self.sum.iter().map(|s| s.map(|c| (c / k) as f32)).collect();
        let var_of_mean = self
            .lum
            .iter()
            .map(|&(s1, s2)| ((s2 / k - (s1 / k).powi(2)) * k / (k - 1.0).max(1.0)).max(0.0) / k)
            .collect();
        VolumeImage {
            width,
            height,
            mean,
            var_of_mean,
            timings,
            paths: (width * height) as u64 * u64::from(spp),
        }
    }
}
