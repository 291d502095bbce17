//! Ray-tracing acceleration structures on the GPU without ray queries: obvhs compressed wide BVHs
//! (CWBVH, Ylitie et al. 2017) in two levels, traversed in WGSL.
//!
//! - [`Blas`]: one CWBVH per [`Mesh`](crate::scene::Mesh), in object space, built once.
//! - [`Tlas`]: one CWBVH over the world-space boxes of the instances, rebuilt when one moves.
//! - [`SceneBvh`]: both levels on the CPU, with a reference traversal through obvhs's own
//!   CWBVH traversal (the ground truth the WGSL traversal is tested against).
//! - [`SceneGeometry`]: the same structures in texel tables (one bind group, `@group(1)`) and
//!   the WGSL interface `scene_geometry.wgsl` that passes import (`SceneGeometry::modules`).
//! - [`RayBatch`]: a compute pass tracing a buffer of rays (tests, benchmark).
//! - [`random_rays`], [`displaced_sphere`]: seeded rays and a procedural mesh (tests, benchmark).

mod blas;
mod build;
mod cpu_traversal;
mod procedural;
mod ray_batch;
mod scene_geometry;
mod stack_need;
mod tlas;
mod triangle;

pub use blas::{Blas, leaf_order, mesh_triangles};
pub use cpu_traversal::{InstanceUpdate, SceneBvh, instance_transforms, obvhs_ray};
pub use procedural::{displaced_sphere, random_rays};
pub use ray_batch::{
    BatchGeometry, RayBatch, RayBuffers, RayQuery, SurfaceRecord, TraceKind,
    struct_layout_mismatches as ray_batch_struct_mismatches,
};
pub use scene::rng::{SplitMix64, mix64};
pub use scene_geometry::{
    LEAF_BOX_PAD, SceneGeometry, SgInstance, SgInstanceHeader, SgMesh, SgNode, SgTlasLeaf,
    SgTriangle, SgVertex, padded_leaf_box, sg_triangles, storage_buffer,
};
pub use tlas::InstanceTransforms;
pub use tlas::{Tlas, world_bounds};
pub use triangle::{WatertightRay, intersect_triangle};

use crate::gpu::GpuError;
use glam::Vec2;

/// Entries of the WGSL traversal stack at most (`SG_STACK_SIZE` in scene_geometry.wgsl). A scene
/// needs [`SceneBvh::stack_entries`] (stack_need.rs); [`SceneBvh`] refuses scenes that could need
/// more, so the shader's overflow guard never drops a node group.
pub const TRAVERSAL_STACK_SIZE: u32 = 32;

/// Marks "no instance" / "no primitive" in a [`Hit`], as `NO_HIT` does in WGSL.
pub const NO_HIT: u32 = u32::MAX;

/// A ray's closest intersection, the CPU twin of WGSL's `Hit`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Hit {
    /// Ray parameter in units of the ray direction; equals the ray's `t_max` on a miss.
    pub t: f32,
    /// Index into `SceneDesc::instances`, [`NO_HIT`] on a miss.
    pub instance: u32,
    /// Triangle index into the mesh's `indices`, [`NO_HIT`] on a miss.
    pub primitive: u32,
    /// (u, v): weights of the triangle's vertices 1 and 2.
    pub barycentrics: Vec2,
}

impl Hit {
    pub fn miss(t_max: f32) -> Self {
        Self { t: t_max, instance: NO_HIT, primitive: NO_HIT, barycentrics: Vec2::ZERO }
    }

    pub fn is_hit(&self) -> bool {
        self.instance != NO_HIT
    }
}

#[derive(Debug, thiserror::Error)]
pub enum BvhError {
    #[error(transparent)]
    Gpu(#[from] GpuError),
    #[error("mesh {index} '{name}': {reason}")]
    Mesh { index: usize, name: String, reason: String },
    #[error("instance {instance} refers to mesh {mesh}, but the scene has {meshes} meshes")]
    InstanceMesh { instance: usize, mesh: u32, meshes: usize },
    #[error("instance {instance} has a non-invertible or non-finite transform {transform}")]
    InstanceTransform { instance: usize, transform: String },
    #[error(
        "instance {instance} (world bounds {bounds}) lies outside its TLAS box by more than f32 rounding: a defect of the BVH build, please report it with this scene"
    )]
    InstanceBounds { instance: usize, bounds: String },
    #[error(
        "BVH too deep for the GPU traversal stack: it can need {needed} entries (TLAS depth {tlas}, deepest BLAS depth {blas} in mesh '{mesh}'), more than the {limit} the stack holds"
    )]
    TooDeep { needed: u32, limit: u32, tlas: u32, blas: u32, mesh: String },
    #[error(
        "this ray batch's traversal stack holds {compiled} entries, and the geometry's BVH can need {needed} (it grew deeper): build a new batch on it"
    )]
    StackTooSmall { compiled: u32, needed: u32 },
    #[error(
        "the adapter allows {limit} storage buffers per shader stage; the scene geometry alone needs {needed}"
    )]
    StorageBuffers { needed: u32, limit: u32 },
    #[error("reading back '{what}' from the GPU failed: {reason}")]
    Readback { what: String, reason: String },
}
