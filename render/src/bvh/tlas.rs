//! Top-level acceleration structure: a CWBVH over the world-space boxes of the instances.
//! Instances move every frame, so it is rebuilt (PLOC over N boxes is cheap next to tracing).

use glam::{Mat4, Vec3, Vec3A};
use obvhs::{BvhBuildParams, aabb::Aabb, cwbvh::CwBvh};

use super::{Blas, BvhError, blas::cwbvh_depth};
use crate::scene::Instance;

/// An instance as traversal and shading need it.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct InstanceTransforms {
    pub object_to_world: Mat4,
    pub world_to_object: Mat4,
    /// Last frame's object-to-world, for motion vectors (equals the current one on frame 0).
    pub previous_object_to_world: Mat4,
    pub mesh: u32,
    pub material: u32,
}

impl InstanceTransforms {
    /// Checks the mesh index and that the transform is finite and invertible.
    pub fn new(index: usize, instance: &Instance, mesh_count: usize) -> Result<Self, BvhError> {
        if instance.mesh as usize >= mesh_count {
            return Err(BvhError::InstanceMesh {
                instance: index,
                mesh: instance.mesh,
                meshes: mesh_count,
            });
        }
        let m = instance.transform;
        let det = m.determinant();
        if !m.is_finite() || !det.is_finite() || det == 0.0 {
            return Err(BvhError::InstanceTransform {
                instance: index,
                transform: format!("{m:?}"),
            });
        }
        Ok(Self {
            object_to_world: m,
            world_to_object: m.inverse(),
            previous_object_to_world: m,
            mesh: instance.mesh,
            material: instance.material,
        })
    }
}

pub struct Tlas {
    /// `bvh.primitive_indices[i]` is an index into the instances (not into the boxes built over).
    pub bvh: CwBvh,
    /// World bounds of all instances with geometry (empty when there are none).
    pub bounds: Aabb,
    pub depth: u32,
    /// Traversal stack entries the two-level traversal can hold (`stack_need.rs`): the TLAS's,
    /// with the neediest BLAS's on top wherever an instance is entered.
    pub stack_need: u32,
}

impl Tlas {
    /// Builds over the instances whose mesh has triangles; the others can never be hit.
    pub fn build(instances: &[InstanceTransforms], blas: &[Blas]) -> Result<Self, BvhError> {
        let mut ids = Vec::with_capacity(instances.len());
        let mut boxes = Vec::with_capacity(instances.len());
        for (i, inst) in instances.iter().enumerate() {
            let b = &blas[inst.mesh as usize];
            if b.triangles.is_empty() {
                continue;
            }
            ids.push(i as u32);
            boxes.push(world_bounds(&inst.object_to_world, &b.bounds));
        }
        if boxes.is_empty() {
            return Ok(Self {
                bvh: CwBvh::default(),
                bounds: Aabb::empty(),
                depth: 0,
                stack_need: 0,
            });
        }
        let mut bvh = super::build::build_cwbvh(&boxes, BvhBuildParams::fast_build());
        let covered = |p: u32, b: &Aabb, scale: Vec3A| {
            let w = &boxes[p as usize];
            super::build::contains(b, w.min, scale) && super::build::contains(b, w.max, scale)
        };
        if let Some(p) = super::build::first_uncovered(&bvh, covered) {
            return Err(BvhError::InstanceBounds {
                instance: ids[p as usize] as usize,
                bounds: format!("{} to {}", boxes[p as usize].min, boxes[p as usize].max),
            });
        }
        for p in &mut bvh.primitive_indices {
            *p = ids[*p as usize];
        }
        let bounds = boxes.iter().fold(Aabb::empty(), |acc, b| acc.union(b));
        let depth = cwbvh_depth(&bvh);
        let stack_need = super::stack_need::tlas_stack_need(
            &bvh,
            blas.iter().map(|b| b.stack_need).max().unwrap_or(0),
        );
        Ok(Self { bvh, bounds, depth, stack_need })
    }
}

/// The world box of an object-space box: the box around its eight transformed corners.
pub fn world_bounds(object_to_world: &Mat4, b: &Aabb) -> Aabb {
    let mut out = Aabb::empty();
    for corner in 0..8 {
        let p = Vec3::new(
            if corner & 1 == 0 { b.min.x } else { b.max.x },
            if corner & 2 == 0 { b.min.y } else { b.max.y },
            if corner & 4 == 0 { b.min.z } else { b.max.z },
        );
        out.extend(Vec3A::from(object_to_world.transform_point3(p)));
    }
    out
}
