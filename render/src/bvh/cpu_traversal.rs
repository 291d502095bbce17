//! Both BVH levels on the CPU, and the reference two-level traversal built on obvhs's own CWBVH
//! traversal (`CwBvh::ray_traverse` / `ray_traverse_miss`) per level: TLAS leaf -> ray into the
//! instance's object space -> BLAS -> watertight triangle test (the same test as the WGSL).

use glam::{Vec2, Vec3, Vec3A};
use obvhs::ray::{Ray, RayHit};

use super::tlas::InstanceTransforms;
use super::{Blas, BvhError, Hit, TRAVERSAL_STACK_SIZE, Tlas, WatertightRay, intersect_triangle};
use crate::scene::{Instance, SceneDesc};

pub struct SceneBvh {
    pub blas: Vec<Blas>,
    pub tlas: Tlas,
    pub instances: Vec<InstanceTransforms>,
    mesh_names: Vec<String>,
}

/// What [`SceneBvh::update_instances`] had to do.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum InstanceUpdate {
    /// Same transforms and materials as last frame, and last frame's previous == current.
    Unchanged,
    /// Nothing moved, but the instance table changed (previous transforms caught up, or a material).
    TableOnly,
    /// Something moved or the instance list changed: the TLAS was rebuilt.
    Rebuilt,
}

impl SceneBvh {
    /// Builds one BLAS per mesh and the TLAS over the scene's instances.
    pub fn new(scene: &SceneDesc) -> Result<Self, BvhError> {
        let blas = scene.meshes.iter().enumerate().map(|(i, m)| Blas::build(i, m)).collect::<Result<Vec<_>, _>>()?;
        let instances = instance_transforms(&scene.instances, blas.len())?;
        let tlas = Tlas::build(&instances, &blas);
        let mesh_names = scene.meshes.iter().map(|m| m.name.clone()).collect();
        let bvh = Self { blas, tlas, instances, mesh_names };
        bvh.check_stack_depth()?;
        Ok(bvh)
    }

    /// Next frame's instances: the current transforms become the previous ones; the TLAS is
    /// rebuilt only if a transform or the instance list changed.
    pub fn update_instances(&mut self, instances: &[Instance]) -> Result<InstanceUpdate, BvhError> {
        let mut next = instance_transforms(instances, self.blas.len())?;
        let same_list = next.len() == self.instances.len()
            && next.iter().zip(&self.instances).all(|(n, o)| n.mesh == o.mesh);
        for (n, o) in next.iter_mut().zip(&self.instances) {
            n.previous_object_to_world = o.object_to_world;
        }
        let moved = !same_list || next.iter().zip(&self.instances).any(|(n, o)| n.object_to_world != o.object_to_world);
        let table_changed = next != self.instances;
        self.instances = next;
        if moved {
            self.tlas = Tlas::build(&self.instances, &self.blas);
            self.check_stack_depth()?;
            Ok(InstanceUpdate::Rebuilt)
        } else if table_changed {
            Ok(InstanceUpdate::TableOnly)
        } else {
            Ok(InstanceUpdate::Unchanged)
        }
    }

    /// Entries the two-level traversal's stack can need: TLAS depth + deepest BLAS depth + 1.
    pub fn stack_entries(&self) -> u32 {
        self.tlas.depth + self.blas.iter().map(|b| b.depth).max().unwrap_or(0) + 1
    }

    fn check_stack_depth(&self) -> Result<(), BvhError> {
        let (deepest, depth) = self.blas.iter().enumerate().map(|(i, b)| (i, b.depth)).max_by_key(|&(_, d)| d).unwrap_or((0, 0));
        if self.stack_entries() > TRAVERSAL_STACK_SIZE {
            return Err(BvhError::TooDeep {
                tlas: self.tlas.depth,
                blas: depth,
                mesh: self.mesh_names.get(deepest).cloned().unwrap_or_default(),
            });
        }
        Ok(())
    }

    /// World bounds of all instances with geometry; (0, 0) for an empty scene.
    pub fn bounds(&self) -> (Vec3, Vec3) {
        if self.tlas.bvh.nodes.is_empty() {
            return (Vec3::ZERO, Vec3::ZERO);
        }
        (self.tlas.bounds.min.into(), self.tlas.bounds.max.into())
    }

    /// Closest hit with `0 < t < t_max` (`t` in units of `direction`).
    pub fn trace_closest(&self, origin: Vec3, direction: Vec3, t_max: f32) -> Hit {
        let mut best = Hit::miss(t_max);
        if self.tlas.bvh.nodes.is_empty() || !(t_max > 0.0) {
            return best;
        }
        let mut tlas_hit = RayHit::none();
        self.tlas.bvh.ray_traverse(obvhs_ray(origin, direction, t_max), &mut tlas_hit, |ray, slot| {
            let instance = self.tlas.bvh.primitive_indices[slot];
            match self.closest_in_instance(instance, origin, direction, ray.tmax) {
                Some((t, primitive, barycentrics)) => {
                    best = Hit { t, instance, primitive, barycentrics };
                    t
                }
                None => f32::INFINITY,
            }
        });
        best
    }

    /// True if anything is hit with `0 < t < t_max`; stops at the first hit found.
    pub fn trace_any(&self, origin: Vec3, direction: Vec3, t_max: f32) -> bool {
        if self.tlas.bvh.nodes.is_empty() || !(t_max > 0.0) {
            return false;
        }
        let missed = self.tlas.bvh.ray_traverse_miss(obvhs_ray(origin, direction, t_max), |_, slot| {
            let instance = self.tlas.bvh.primitive_indices[slot];
            if self.any_in_instance(instance, origin, direction, t_max) { 0.0 } else { f32::INFINITY }
        });
        !missed
    }

    fn object_ray(&self, instance: u32, origin: Vec3, direction: Vec3) -> (&Blas, Vec3, Vec3) {
        let inst = &self.instances[instance as usize];
        let o = inst.world_to_object.transform_point3(origin);
        // Not normalised: t stays the same parameter in both spaces.
        let d = inst.world_to_object.transform_vector3(direction);
        (&self.blas[inst.mesh as usize], o, d)
    }

    fn closest_in_instance(&self, instance: u32, origin: Vec3, direction: Vec3, t_max: f32) -> Option<(f32, u32, Vec2)> {
        let (blas, o, d) = self.object_ray(instance, origin, direction);
        let tri_ray = WatertightRay::new(o, d);
        let mut found = None;
        let mut hit = RayHit::none();
        blas.bvh.ray_traverse(obvhs_ray(o, d, t_max), &mut hit, |ray, slot| {
            let [a, b, c] = blas.triangles[slot];
            match intersect_triangle(&tri_ray, a, b, c, ray.tmax) {
                Some((t, uv)) => {
                    found = Some((t, blas.bvh.primitive_indices[slot], uv));
                    t
                }
                None => f32::INFINITY,
            }
        });
        found
    }

    fn any_in_instance(&self, instance: u32, origin: Vec3, direction: Vec3, t_max: f32) -> bool {
        let (blas, o, d) = self.object_ray(instance, origin, direction);
        let tri_ray = WatertightRay::new(o, d);
        !blas.bvh.ray_traverse_miss(obvhs_ray(o, d, t_max), |_, slot| {
            let [a, b, c] = blas.triangles[slot];
            intersect_triangle(&tri_ray, a, b, c, t_max).map_or(f32::INFINITY, |(t, _)| t)
        })
    }
}

pub(super) fn instance_transforms(instances: &[Instance], mesh_count: usize) -> Result<Vec<InstanceTransforms>, BvhError> {
    instances.iter().enumerate().map(|(i, inst)| InstanceTransforms::new(i, inst, mesh_count)).collect()
}

/// obvhs's ray; `+ 0.0` turns a -0.0 direction component into +0.0 so that obvhs's octant (sign
/// test) and its reciprocal (sign bit) agree, as they do in the WGSL.
pub(super) fn obvhs_ray(origin: Vec3, direction: Vec3, t_max: f32) -> Ray {
    Ray::new(Vec3A::from(origin), Vec3A::from(direction + Vec3::ZERO), 0.0, t_max)
}
