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
//! - [`SceneBvh2`], [`Bvh2Geometry`]: the same two levels as obvhs binary BVHs (BVH2) with
//!   their CPU reference and WGSL traversal (`bvh2_traversal.wgsl`), measured against the CWBVH
//!   in the benchmark; the path tracer does not use them.
//! - [`traversal_benchmark`]: rays/s of the WGSL traversal against obvhs on all CPU cores, on
//!   random rays and on the same rays sorted for coherence ([`ray_order`]).

mod bench;
mod blas;
mod bvh2;
mod bvh2_geometry;
mod cpu_traversal;
mod ray_batch;
pub mod ray_order;
mod scene_geometry;
mod stack_need;
mod tlas;
mod triangle;

pub use bench::{
    PAIRED_ROUNDS, TraversalBench, displaced_sphere, median, random_rays, traversal_benchmark,
};
pub use blas::Blas;
pub use bvh2::{BVH2_STACK_SIZE, Bvh2Blas, SceneBvh2};
pub use bvh2_geometry::{Bvh2Geometry, SgBvh2Node};
pub use cpu_traversal::{InstanceUpdate, SceneBvh};
pub use ray_batch::{
    BatchGeometry, Bvh2Traversal, RayBatch, RayBuffers, RayQuery, SurfaceRecord, TraceKind,
    struct_layout_mismatches as ray_batch_struct_mismatches,
};
pub use scene::rng::{SplitMix64, mix64};
pub use scene_geometry::{
    SceneGeometry, SgInstance, SgInstanceHeader, SgMesh, SgNode, SgTlasLeaf, SgTriangle, SgVertex,
};
pub use tlas::InstanceTransforms;
pub use tlas::Tlas;
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
