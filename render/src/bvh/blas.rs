//! Bottom-level acceleration structure: one CWBVH per mesh, in object space, built once.

use glam::{Vec3, Vec3A};
use obvhs::{BvhBuildParams, aabb::Aabb, cwbvh::CwBvh, triangle::Triangle};

use super::BvhError;
use crate::scene::Mesh;

pub struct Blas {
    pub bvh: CwBvh,
    /// Triangle vertices in BVH leaf order: `triangles[i]` is the mesh triangle
    /// `bvh.primitive_indices[i]`, so traversal reads vertices without an indirection.
    pub triangles: Vec<[Vec3; 3]>,
    /// Object-space bounds (empty for a mesh without triangles).
    pub bounds: Aabb,
    /// Node levels from the root to the deepest node (0 without triangles).
    pub depth: u32,
    /// Traversal stack entries its traversal can hold (`stack_need.rs`).
    pub stack_need: u32,
}

impl Blas {
    /// Builds the CWBVH of `mesh` (`index` is only for error messages). A mesh without triangles
    /// gives an empty BLAS that no ray hits.
    pub fn build(index: usize, mesh: &Mesh) -> Result<Self, BvhError> {
        let tris = mesh_triangles(index, mesh)?;
        if tris.is_empty() {
            return Ok(Self {
                bvh: CwBvh::default(),
                triangles: Vec::new(),
                bounds: Aabb::empty(),
                depth: 0,
                stack_need: 0,
            });
        }
        let bvh = super::build::build_cwbvh(&tris, BvhBuildParams::medium_build());
        let covered = |p: u32, b: &Aabb, scale: Vec3A| {
            let t = &tris[p as usize];
            [t.v0, t.v1, t.v2].iter().all(|v| super::build::contains(b, *v, scale))
        };
        if let Some(t) = super::build::first_uncovered(&bvh, covered) {
            let tri = &tris[t as usize];
            return Err(BvhError::Mesh {
                index,
                name: mesh.name.clone(),
                reason: format!(
                    "triangle {t} ({}, {}, {}) lies outside its BVH box by more than f32 rounding: a defect of the BVH build, please report it with this mesh",
                    tri.v0, tri.v1, tri.v2
                ),
            });
        }
        let triangles = leaf_order(&bvh.primitive_indices, &tris);
        let depth = cwbvh_depth(&bvh);
        let stack_need = super::stack_need::blas_stack_need(&bvh);
        Ok(Self { bounds: bvh.total_aabb, bvh, triangles, depth, stack_need })
    }
}

/// The largest coordinate a mesh's position may have (see [`mesh_triangles`]).
pub const MAX_COORDINATE: f32 = 1e18;

/// A mesh's triangles for obvhs, after checking its indices, positions, and per-vertex
/// attribute counts (`index` only for error messages).
pub fn mesh_triangles(index: usize, mesh: &Mesh) -> Result<Vec<Triangle>, BvhError> {
    let err = |reason: String| BvhError::Mesh { index, name: mesh.name.clone(), reason };
    if let Some(i) = mesh.positions.iter().position(|p| !p.is_finite()) {
        return Err(err(format!("position {i} is not finite: {}", mesh.positions[i])));
    }
    // Beyond this the builder's surface areas (squared extents) overflow f32 and its SAH
    // decisions become NaN (obvhs then indexes out of range).
    if let Some(i) = mesh.positions.iter().position(|p| p.abs().max_element() > MAX_COORDINATE) {
        return Err(err(format!(
            "position {i} is {}; expected coordinates within ±{MAX_COORDINATE:e}",
            mesh.positions[i]
        )));
    }
    let n = mesh.positions.len() as u32;
    let mut tris = Vec::with_capacity(mesh.indices.len());
    for (t, idx) in mesh.indices.iter().enumerate() {
        if let Some(&bad) = idx.iter().find(|&&i| i >= n) {
            return Err(err(format!(
                "triangle {t} uses vertex {bad}, but the mesh has {n} positions"
            )));
        }
        let [a, b, c] = idx.map(|i| Vec3A::from(mesh.positions[i as usize]));
        tris.push(Triangle { v0: a, v1: b, v2: c });
    }
    if !mesh.normals.is_empty() && mesh.normals.len() != mesh.positions.len() {
        return Err(err(format!(
            "{} normals for {} positions (expected one per position, or none)",
            mesh.normals.len(),
            n
        )));
    }
    if !mesh.uvs.is_empty() && mesh.uvs.len() != mesh.positions.len() {
        return Err(err(format!(
            "{} uvs for {} positions (expected one per position, or none)",
            mesh.uvs.len(),
            n
        )));
    }
    Ok(tris)
}

/// The triangles' vertices in leaf order (`primitive_indices[i]` is the triangle of slot `i`), so
/// that traversal reads them without an indirection.
pub fn leaf_order(primitive_indices: &[u32], tris: &[Triangle]) -> Vec<[Vec3; 3]> {
    primitive_indices
        .iter()
        .map(|&p| {
            [tris[p as usize].v0.into(), tris[p as usize].v1.into(), tris[p as usize].v2.into()]
        })
        .collect()
}

/// Node levels of a CWBVH: the bound on traversal stack entries one level of traversal needs.
pub(crate) fn cwbvh_depth(bvh: &CwBvh) -> u32 {
    if bvh.nodes.is_empty() {
        return 0;
    }
    let mut deepest = 0;
    let mut todo = vec![(0u32, 1u32)];
    while let Some((node_index, depth)) = todo.pop() {
        deepest = deepest.max(depth);
        let node = &bvh.nodes[node_index as usize];
        for child in 0..8 {
            if !node.is_child_empty(child) && !node.is_leaf(child) {
                todo.push((node.child_node_index(child), depth + 1));
            }
        }
    }
    deepest
}
