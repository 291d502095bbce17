//! A medium on the GPU: its parameters, voxel densities and super-voxels (storage),
//! bound as @group(0) of every media pass.

use bytemuck::Zeroable;
use render::compute::{BufferBinding, binding_layout, buffer_group};
use render::gpu::Gpu;

use crate::medium::{Medium, Segment};

render::gpu_struct! {
    /// One medium's grid shape and box, and where its voxels and super-voxels start in the
    /// shared buffers (several media bound at once: `MAX_MEDIA` of these in one array).
    pub struct MediumParams {
        pub res: [u32; 3] => "vec3u",
        pub density_offset: u32 => "u32",
        /// Super-voxels per axis.
        pub dims: [u32; 3] => "vec3u",
        pub super_voxel_offset: u32 => "u32",
        pub box_min: [f32; 3] => "vec3f",
        /// Media bound (the same in every element).
        pub count: u32 => "u32",
        pub box_max: [f32; 3] => "vec3f",
        /// Voxels per super-voxel edge.
        pub super_voxel: u32 => "u32",
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

/// The most media one pass binds (an array of fixed length; a scenario with more is refused).
pub const MAX_MEDIA: usize = 8;

const _: () =
    assert!(MAX_MEDIA == 8, "update the WGSL array lengths of the media and optics parameters");

pub const BINDINGS: [BufferBinding; 3] = [
    // 8 = MAX_MEDIA (a const string cannot be formatted; the assertion above keeps them equal).
    BufferBinding::read("media", "array<MediumParams, 8>"),
    // every medium's voxels, one after the other
    BufferBinding::read("density", "array<f32>"),
    // min, max, mean, RMS of μ − μ_min, every medium's one after the other
    BufferBinding::read("super_voxels", "array<vec4f>"),
];

/// One or several media on the GPU; shaders select one (`select_medium` in media_grid.wgsl,
/// the first by default).
pub struct GpuMedium {
    pub layout: wgpu::BindGroupLayout,
    pub group: wgpu::BindGroup,
    pub count: usize,
}

impl GpuMedium {
    pub fn new(gpu: &Gpu, medium: &Medium) -> Self {
        Self::several(gpu, &[medium])
    }

    /// Up to [`MAX_MEDIA`] media bound together (their buffers concatenated).
    pub fn several(gpu: &Gpu, media: &[&Medium]) -> Self {
        assert!(
            (1..=MAX_MEDIA).contains(&media.len()),
            "{} media; a pass binds 1 to {MAX_MEDIA}",
            media.len()
        );
        let mut params = [MediumParams::zeroed(); MAX_MEDIA];
        let (mut density, mut sv) = (Vec::new(), Vec::new());
        for (p, medium) in params.iter_mut().zip(media) {
            let g = &medium.density;
            *p = MediumParams {
                res: g.res.into(),
                density_offset: density.len() as u32,
                dims: medium.super_voxels.dims.into(),
                super_voxel_offset: sv.len() as u32,
                box_min: g.box_min.into(),
                count: media.len() as u32,
                box_max: g.box_max.into(),
                super_voxel: medium.super_voxels.size,
            };
            density.extend_from_slice(&g.data);
            sv.extend(
                medium.super_voxels.cells.iter().map(|c| [c.min, c.max, c.mean, c.rms_excess]),
            );
        }
        let buffer = |label: &str, contents: &[u8]| {
            gpu.buffer_init(label, contents, wgpu::BufferUsages::STORAGE)
        };
        let params = buffer("media params", bytemuck::cast_slice(&params));
        let density = buffer("media density", bytemuck::cast_slice(&density));
        let super_voxels = buffer("media super-voxels", bytemuck::cast_slice(&sv));
        let layout = binding_layout(gpu, "media", &BINDINGS);
        let group = buffer_group(gpu, "media", &layout, &[&params, &density, &super_voxels]);
        Self { layout, group, count: media.len() }
    }
}
