//! Binary BVHs (obvhs's `Bvh2`) in two levels, the alternative to the CWBVH
//! to measure: one BVH2 per mesh over its triangles (the same obvhs build parameters as
//! [`Blas`](render::bvh::Blas)) and one over the instances' world boxes, with a CPU reference
//! traversal through obvhs's own `Bvh2::ray_traverse` per level. Only the traversal tests and
//! the benchmark use it; the path tracer traverses the CWBVH.
//!
//! Departures from the CWBVH levels, both from the format: a BVH2 leaf holds up to 8 triangles
//! (`max_prims_per_leaf` of `medium_build`; a CWBVH leaf holds at most 3), and the TLAS is built
//! with one instance per leaf so that a leaf names its instance directly.

use std::time::Duration;

use glam::{Vec2, Vec3};
use obvhs::{
    BvhBuildParams,
    aabb::Aabb,
    bvh2::Bvh2,
    bvh2::builder::{build_bvh2, build_bvh2_from_tris},
    ray::RayHit,
};

use render::bvh::{
    BvhError, Hit, InstanceTransforms, WatertightRay, instance_transforms, intersect_triangle,
    leaf_order, mesh_triangles, obvhs_ray, world_bounds,
};
use render::scene::SceneDesc;

/// Entries of the WGSL BVH2 traversal stack (`BVH2_STACK_SIZE` in bvh2_traversal.wgsl): one per
/// level at most (the far child of each inner node on the path), so a two-level traversal needs
/// `tlas depth + blas depth` entries; [`SceneBvh2::new`] refuses scenes that could need more.
pub const BVH2_STACK_SIZE: u32 = 64;

/// One mesh's BVH2, in object space.
pub struct Bvh2Blas {
    pub bvh: Bvh2,
    /// Triangle vertices in leaf order: `triangles[i]` is mesh triangle `bvh.primitive_indices[i]`.
    pub triangles: Vec<[Vec3; 3]>,
    pub bounds: Aabb,
    /// Node levels from the root to the deepest leaf (0 without triangles).
    pub depth: u32,
}

pub struct SceneBvh2 {
    pub blas: Vec<Bvh2Blas>,
    /// Over the instances with triangles; `tlas.primitive_indices[i]` is an instance index.
    pub tlas: Bvh2,
    pub tlas_depth: u32,
    pub instances: Vec<InstanceTransforms>,
}

impl Bvh2Blas {
    /// The BVH2 of a mesh's triangles (`index` only for error messages), checked as in
    /// [`Blas::build`](render::bvh::Blas::build).
    pub fn build(index: usize, mesh: &render::scene::Mesh) -> Result<Self, BvhError> {
        let tris = mesh_triangles(index, mesh)?;
        if tris.is_empty() {
            return Ok(Self {
                bvh: Bvh2::default(),
                triangles: Vec::new(),
                bounds: Aabb::empty(),
                depth: 0,
            });
        }
        let bvh =
            build_bvh2_from_tris(&tris, BvhBuildParams::medium_build(), &mut Duration::default());
        let triangles = leaf_order(&bvh.primitive_indices, &tris);
        let depth = bvh2_depth(&bvh);
        Ok(Self { bounds: *bvh.nodes[0].aabb(), bvh, triangles, depth })
    }
}

impl SceneBvh2 {
    /// Builds one BVH2 per mesh and one over the instances (the same instances, checked the same
    /// way, as [`SceneBvh::new`](render::bvh::SceneBvh::new)).
    pub fn new(scene: &SceneDesc) -> Result<Self, BvhError> {
        let blas = scene
            .meshes
            .iter()
            .enumerate()
            .map(|(i, m)| Bvh2Blas::build(i, m))
            .collect::<Result<Vec<_>, _>>()?;
        let instances = instance_transforms(&scene.instances, blas.len())?;
        let mut ids = Vec::new();
        let mut boxes = Vec::new();
        for (i, inst) in instances.iter().enumerate() {
            let b = &blas[inst.mesh as usize];
            if !b.triangles.is_empty() {
                ids.push(i as u32);
                boxes.push(world_bounds(&inst.object_to_world, &b.bounds));
            }
        }
        let mut tlas = Bvh2::default();
        if !boxes.is_empty() {
            let params = BvhBuildParams { max_prims_per_leaf: 1, ..BvhBuildParams::fast_build() };
            tlas = build_bvh2(&boxes, params, &mut Duration::default());
            for p in &mut tlas.primitive_indices {
                *p = ids[*p as usize];
            }
        }
        let tlas_depth = bvh2_depth(&tlas);
        let deepest = blas.iter().enumerate().max_by_key(|(_, b)| b.depth);
        if let Some((i, b)) = deepest
            && tlas_depth + b.depth > BVH2_STACK_SIZE
        {
            return Err(BvhError::TooDeep {
                needed: tlas_depth + b.depth,
                limit: BVH2_STACK_SIZE,
                tlas: tlas_depth,
                blas: b.depth,
                mesh: scene.meshes[i].name.clone(),
            });
        }
        // The GPU layout stores a TLAS leaf's instance in place of its first primitive slot.
        assert!(
            tlas.nodes.iter().all(|n| !n.is_leaf() || n.prim_count == 1),
            "a BVH2 TLAS leaf with more than one instance"
        );
        Ok(Self { blas, tlas, tlas_depth, instances })
    }

    /// Closest hit with `0 < t < t_max` (`t` in units of `direction`), through obvhs's
    /// `Bvh2::ray_traverse` on both levels and the watertight triangle test.
    pub fn trace_closest(&self, origin: Vec3, direction: Vec3, t_max: f32) -> Hit {
        let mut best = Hit::miss(t_max);
        if self.tlas.nodes.is_empty() || !(t_max > 0.0) {
            return best;
        }
        self.tlas.ray_traverse(
            obvhs_ray(origin, direction, t_max),
            &mut RayHit::none(),
            |r, slot| {
                let instance = self.tlas.primitive_indices[slot];
                match self.closest_in_instance(instance, origin, direction, r.tmax) {
                    Some((t, primitive, barycentrics)) => {
                        best = Hit { t, instance, primitive, barycentrics };
                        t
                    }
                    None => f32::INFINITY,
                }
            },
        );
        best
    }

    /// True if anything is hit with `0 < t < t_max`.
    pub fn trace_any(&self, origin: Vec3, direction: Vec3, t_max: f32) -> bool {
        if self.tlas.nodes.is_empty() || !(t_max > 0.0) {
            return false;
        }
        !self.tlas.ray_traverse_miss(obvhs_ray(origin, direction, t_max), |_, slot| {
            let instance = self.tlas.primitive_indices[slot];
            if self.closest_in_instance(instance, origin, direction, t_max).is_some() {
                0.0
            } else {
                f32::INFINITY
            }
        })
    }

    fn closest_in_instance(
        &self,
        instance: u32,
        origin: Vec3,
        direction: Vec3,
        t_max: f32,
    ) -> Option<(f32, u32, Vec2)> {
        let inst = &self.instances[instance as usize];
        let blas = &self.blas[inst.mesh as usize];
        let o = inst.world_to_object.transform_point3(origin);
        // Not normalised: t stays the same parameter in both spaces.
        let d = inst.world_to_object.transform_vector3(direction);
        let tri_ray = WatertightRay::new(o, d);
        let mut found = None;
        blas.bvh.ray_traverse(obvhs_ray(o, d, t_max), &mut RayHit::none(), |r, slot| {
            let [a, b, c] = blas.triangles[slot];
            match intersect_triangle(&tri_ray, a, b, c, r.tmax) {
                Some((t, uv)) => {
                    found = Some((t, blas.bvh.primitive_indices[slot], uv));
                    t
                }
                None => f32::INFINITY,
            }
        });
        found
    }
}

/// Node levels from the root to the deepest leaf (0 for an empty BVH2).
fn bvh2_depth(bvh: &Bvh2) -> u32 {
    if bvh.nodes.is_empty() {
        return 0;
    }
    let mut deepest = 0;
    let mut todo = vec![(0u32, 1u32)];
    while let Some((index, depth)) = todo.pop() {
        deepest = deepest.max(depth);
        let node = &bvh.nodes[index as usize];
        if !node.is_leaf() {
            todo.push((node.first_index, depth + 1));
            todo.push((node.first_index + 1, depth + 1));
        }
    }
    deepest
}
