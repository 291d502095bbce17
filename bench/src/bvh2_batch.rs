//! The ray batch (`render::bvh::RayBatch`) over the BVH2 traversal: the same kernels with
//! `package::ray_batch::trace` filled by `shaders/ray_batch/bvh2.wgsl`.

use render::bvh::{BatchGeometry, RayBatch, SceneGeometry};
use render::gpu::Gpu;

use crate::bvh2_geometry::Bvh2Geometry;

/// The BVH2 traversal's geometry: the scene's (@group(1): instances, ray set-up, triangle test)
/// and its BVH2s (@group(2)).
pub struct Bvh2Traversal<'a> {
    pub geometry: &'a SceneGeometry,
    pub bvh2: &'a Bvh2Geometry,
}

impl BatchGeometry for Bvh2Traversal<'_> {
    fn bind_groups(&self) -> Vec<&wgpu::BindGroup> {
        vec![self.geometry.bind_group(), self.bvh2.bind_group()]
    }

    fn stack_entries(&self) -> u32 {
        self.geometry.stack_entries()
    }
}

impl Bvh2Traversal<'_> {
    /// The batch of the BVH2 traversal (bvh2_traversal.wgsl).
    pub fn batch(&self, gpu: &Gpu) -> RayBatch {
        let modules = [SceneGeometry::modules(), Bvh2Geometry::modules()].concat();
        let layouts = [self.geometry.bind_group_layout(), self.bvh2.bind_group_layout()];
        RayBatch::with_traversal(
            gpu,
            modules,
            render::wgsl_file!("ray_batch/bvh2.wgsl"),
            &layouts,
            self.geometry.stack_entries(),
        )
    }
}
