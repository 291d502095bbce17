//! Primary-ray transmittance images on the GPU: one estimate per (pixel, sample) of one
//! estimator, camera rays clipped to the medium's box in WGSL (media_image.wgsl). The results
//! come back per estimate, as `image::estimates` gives them on the CPU.

use glam::Vec3;
use render::compute::{BufferBinding, binding_layout, buffer_group, pipelines};
use render::error::RenderError;
use render::gpu::Gpu;
use render::gpu_struct::GpuStruct;
use render::readback::Staging;
use render::timing::{PassTimer, PassTiming};

use super::medium::GpuMedium;
use crate::image::{ImageKey, T_MAX};
use crate::medium::Estimate;
use crate::transmittance::Estimator;

render::gpu_struct! {
    pub struct ImageParams {
        pub origin: [f32; 3] => "vec3f",
        pub t_max: f32 => "f32",
        pub width: u32 => "u32",
        pub height: u32 => "u32",
        pub spp: u32 => "u32",
        pub seed: u32 => "u32",
        pub frame: u32 => "u32",
        pub kind: u32 => "u32",
        pub samples: u32 => "u32",
        pub multiplier: f32 => "f32",
    }
}

const BINDINGS: [BufferBinding; 3] = [
    BufferBinding::read("image", "ImageParams"),
    BufferBinding::read("directions", "array<vec4f>"),
    BufferBinding::read_write("results", "array<vec2u>"),
];

/// The pass's name in frames.csv (`gpu_ms_media_transmittance`).
pub const PASS: &str = "media_transmittance";

pub struct ImagePass {
    timer: PassTimer,
    layout: wgpu::BindGroupLayout,
    pipeline: wgpu::ComputePipeline,
}

impl ImagePass {
    pub fn new(gpu: &Gpu, medium: &GpuMedium) -> Result<Self, RenderError> {
        let layout = binding_layout(gpu, "media image", &BINDINGS);
        let program = super::shaders::program(
            "image",
            ImageParams::WGSL,
            &BINDINGS,
            render::wgsl_file!("media_image.wgsl"),
        );
        let [pipeline] = pipelines(
            gpu,
            "media image",
            &program,
            &[&medium.layout, &layout],
            ["transmittance_image"],
        )?;
        Ok(Self { timer: PassTimer::new(gpu, &[PASS]), layout, pipeline })
    }

    /// The estimates of every (pixel, sample), pixel-major, and the pass's time.
    #[allow(clippy::too_many_arguments)]
    pub fn run(
        &self,
        gpu: &Gpu,
        medium: &GpuMedium,
        origin: Vec3,
        dirs: &[Vec3],
        width: u32,
        estimator: Estimator,
        key: ImageKey,
    ) -> Result<(Vec<Estimate>, Vec<PassTiming>), String> {
        let height = dirs.len() as u32 / width;
        let (kind, samples, multiplier) = estimator.gpu_settings();
        let params = ImageParams {
            origin: origin.into(),
            t_max: T_MAX,
            width,
            height,
            spp: key.spp,
            seed: key.seed,
            frame: key.frame,
            kind,
            samples,
            multiplier,
        };
        let device = &gpu.device;
        let init = |label: &str, contents: &[u8]| {
            gpu.buffer_init(label, contents, wgpu::BufferUsages::STORAGE)
        };
        let params = init("media image params", bytemuck::bytes_of(&params));
        let d4: Vec<[f32; 4]> = dirs.iter().map(|d| [d.x, d.y, d.z, 0.0]).collect();
        let dirs_buf = init("media image directions", bytemuck::cast_slice(&d4));
        let count = dirs.len() as u64 * u64::from(key.spp);
        gpu.check_buffer_size("media image results", count * 8).map_err(|e| e.to_string())?;
        let size = count * 8;
        let results = device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("media image results"),
            size,
            usage: wgpu::BufferUsages::STORAGE | wgpu::BufferUsages::COPY_SRC,
            mapped_at_creation: false,
        });
        let group = buffer_group(gpu, "media image", &self.layout, &[&params, &dirs_buf, &results]);
        let groups = (count as u32).div_ceil(64);
        let mut timed = self.timer.begin(gpu, "media image");
        timed
            .pass(0, |pass| {
                pass.set_pipeline(&self.pipeline);
                pass.set_bind_group(0, &medium.group, &[]);
                pass.set_bind_group(1, &group, &[]);
                pass.dispatch_workgroups(groups.min(65535), groups.div_ceil(65535), 1);
            })
            .map_err(|e| e.to_string())?;
        let staging = Staging::copy_of(gpu, timed.encoder(), &results, "media image results");
        let timings = timed.submit().map_err(|e| e.to_string())?;
        let raw: Vec<[u32; 2]> = staging.read(gpu).map_err(|e| e.to_string())?;
        Ok((
            raw.into_iter()
                .map(|[v, l]| Estimate { value: f32::from_bits(v), lookups: l })
                .collect(),
            timings,
        ))
    }
}
