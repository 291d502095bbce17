//! One estimator on a list of segments, each with its own seed: the GPU twin of calling
//! `Estimator::estimate` with `Pcg::new(seed)` per segment.

use render::compute::{BufferBinding, binding_layout, buffer_group, pipelines};
use render::error::RenderError;
use render::gpu::Gpu;
use render::readback::Staging;

use media::Estimator;
use media::gpu::{GpuMedium, RaySegment};

render::gpu_struct! {
    pub struct RayParams {
        pub count: u32 => "u32",
        pub kind: u32 => "u32",
        pub samples: u32 => "u32",
        pub multiplier: f32 => "f32",
    }
}

const BINDINGS: [BufferBinding; 4] = [
    BufferBinding::read("ray_params", "RayParams"),
    BufferBinding::read("rays", "array<RaySegment>"),
    BufferBinding::read("seeds", "array<u32>"),
    BufferBinding::read_write("results", "array<vec2u>"),
];

/// One segment's estimate and its density lookups.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct RayResult {
    pub value: f32,
    pub lookups: u32,
}

pub struct EstimatorPass {
    layout: wgpu::BindGroupLayout,
    pipeline: wgpu::ComputePipeline,
}

impl EstimatorPass {
    pub fn new(gpu: &Gpu, medium: &GpuMedium) -> Result<Self, RenderError> {
        use render::gpu_struct::GpuStruct;
        let layout = binding_layout(gpu, "media rays", &BINDINGS);
        let program = media::gpu::program(
            "rays",
            RayParams::WGSL,
            &BINDINGS,
            super::module("rays", include_str!("rays.wgsl")),
        );
        let [pipeline] =
            pipelines(gpu, "media rays", &program, &[&medium.layout, &layout], ["estimate_rays"])?;
        Ok(Self { layout, pipeline })
    }

    pub fn run(
        &self,
        gpu: &Gpu,
        medium: &GpuMedium,
        estimator: Estimator,
        rays: &[RaySegment],
        seeds: &[u32],
    ) -> Result<Vec<RayResult>, String> {
        assert_eq!(rays.len(), seeds.len());
        let (kind, samples, multiplier) = estimator.gpu_settings();
        let params = RayParams { count: rays.len() as u32, kind, samples, multiplier };
        let device = &gpu.device;
        let init = |label: &str, contents: &[u8]| {
            gpu.buffer_init(label, contents, wgpu::BufferUsages::STORAGE)
        };
        let params = init("ray params", bytemuck::bytes_of(&params));
        let rays_buf = init("rays", bytemuck::cast_slice(rays));
        let seeds_buf = init("seeds", bytemuck::cast_slice(seeds));
        let size = (rays.len() * 8) as u64;
        let results = device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("results"),
            size,
            usage: wgpu::BufferUsages::STORAGE | wgpu::BufferUsages::COPY_SRC,
            mapped_at_creation: false,
        });
        let group = buffer_group(
            gpu,
            "media rays",
            &self.layout,
            &[&params, &rays_buf, &seeds_buf, &results],
        );
        let mut enc = device.create_command_encoder(&Default::default());
        {
            let mut pass = enc.begin_compute_pass(&Default::default());
            pass.set_pipeline(&self.pipeline);
            pass.set_bind_group(0, &medium.group, &[]);
            pass.set_bind_group(1, &group, &[]);
            pass.dispatch_workgroups((rays.len() as u32).div_ceil(64), 1, 1);
        }
        let staging = Staging::copy_of(gpu, &mut enc, &results, "media ray results");
        gpu.queue.submit([enc.finish()]);
        let raw: Vec<[u32; 2]> = staging.read(gpu).map_err(|e| e.to_string())?;
        Ok(raw
            .into_iter()
            .map(|[v, l]| RayResult { value: f32::from_bits(v), lookups: l })
            .collect())
    }
}
