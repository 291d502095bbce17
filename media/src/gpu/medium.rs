//! A medium on the GPU: its parameters (uniform), voxel densities and super-voxels (storage),
//! bound as @group(0) of every media pass.

use render::compute::{BufferBinding, binding_layout, buffer_group};
use render::gpu::Gpu;
use wgpu::util::DeviceExt;

use crate::medium::{Medium, Segment};

render::gpu_struct! {
    /// The grid's shape and box.
    pub struct MediumParams {
        pub res: [u32; 3] => "vec3u",
        pub _pad0: u32 => "u32",
        /// Super-voxels per axis.
        pub dims: [u32; 3] => "vec3u",
        pub _pad1: u32 => "u32",
        pub box_min: [f32; 3] => "vec3f",
        pub _pad2: f32 => "f32",
        pub box_max: [f32; 3] => "vec3f",
        pub _pad3: f32 => "f32",
    }
}

render::gpu_struct! {
    /// media::Segment on the GPU: texel-space origin and direction, [t0, t1] in world units.
    #[derive(Default, PartialEq)]
    pub struct RaySegment {
        pub origin: [f32; 3] => "vec3f",
        pub t0: f32 => "f32",
        pub dir: [f32; 3] => "vec3f",
        pub t1: f32 => "f32",
    }
}

impl From<&Segment> for RaySegment {
    fn from(s: &Segment) -> Self {
        Self { origin: s.origin.into(), t0: s.t0, dir: s.dir.into(), t1: s.t1 }
    }
}

pub const BINDINGS: [BufferBinding; 3] = [
    BufferBinding::uniform("medium", "MediumParams"),
    BufferBinding::read("density", "array<f32>"),
    // min, max, mean, RMS of μ − μ_min
    BufferBinding::read("super_voxels", "array<vec4f>"),
];

pub struct GpuMedium {
    pub layout: wgpu::BindGroupLayout,
    pub group: wgpu::BindGroup,
}

impl GpuMedium {
    pub fn new(gpu: &Gpu, medium: &Medium) -> Self {
        let g = &medium.density;
        let params = MediumParams {
            res: g.res.into(),
            _pad0: 0,
            dims: medium.super_voxels.dims.into(),
            _pad1: 0,
            box_min: g.box_min.into(),
            _pad2: 0.0,
            box_max: g.box_max.into(),
            _pad3: 0.0,
        };
        let sv: Vec<[f32; 4]> = medium.super_voxels.cells.iter().map(|c| [c.min, c.max, c.mean, c.rms_excess]).collect();
        let buffer = |label: &str, contents: &[u8], usage| gpu.device.create_buffer_init(&wgpu::util::BufferInitDescriptor { label: Some(label), contents, usage });
        let params = buffer("media params", bytemuck::bytes_of(&params), wgpu::BufferUsages::UNIFORM);
        let density = buffer("media density", bytemuck::cast_slice(&g.data), wgpu::BufferUsages::STORAGE);
        let super_voxels = buffer("media super-voxels", bytemuck::cast_slice(&sv), wgpu::BufferUsages::STORAGE);
        let layout = binding_layout(gpu, "media", &BINDINGS);
        let group = buffer_group(gpu, "media", &layout, &[&params, &density, &super_voxels]);
        Self { layout, group }
    }
}
