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
        let blas = scene
            .meshes
            .iter()
            .enumerate()
            .map(|(i, m)| Blas::build(i, m))
            .collect::<Result<Vec<_>, _>>()?;
        let instances = instance_transforms(&scene.instances, blas.len())?;
        let tlas = Tlas::build(&instances, &blas)?;
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
        let moved = !same_list
            || next
                .iter()
                .zip(&self.instances)
                .any(|(n, o)| n.object_to_world != o.object_to_world);
        let table_changed = next != self.instances;
        self.instances = next;
        if moved {
            self.tlas = Tlas::build(&self.instances, &self.blas)?;
            self.check_stack_depth()?;
            Ok(InstanceUpdate::Rebuilt)
        } else if table_changed {
            Ok(InstanceUpdate::TableOnly)
        } else {
            Ok(InstanceUpdate::Unchanged)
        }
    }

    /// Entries the two-level traversal's stack can hold ([`Tlas::stack_need`], computed when the
    /// TLAS is built).
    pub fn stack_entries(&self) -> u32 {
        self.tlas.stack_need
    }

    fn check_stack_depth(&self) -> Result<(), BvhError> {
        let (deepest, depth) = self
            .blas
            .iter()
            .enumerate()
            .map(|(i, b)| (i, b.depth))
            .max_by_key(|&(_, d)| d)
            .unwrap_or((0, 0));
        let needed = self.stack_entries();
        if needed > TRAVERSAL_STACK_SIZE {
            return Err(BvhError::TooDeep {
                needed,
                limit: TRAVERSAL_STACK_SIZE,
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
        self.tlas.bvh.ray_traverse(
            obvhs_ray(origin, direction, t_max),
            &mut tlas_hit,
            |ray, slot| {
                let instance = self.tlas.bvh.primitive_indices[slot];
                match self.closest_in_instance(instance, origin, direction, ray.tmax) {
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

    /// True if anything is hit with `0 < t < t_max`; stops at the first hit found.
    pub fn trace_any(&self, origin: Vec3, direction: Vec3, t_max: f32) -> bool {
        if self.tlas.bvh.nodes.is_empty() || !(t_max > 0.0) {
            return false;
        }
        let missed =
            self.tlas.bvh.ray_traverse_miss(obvhs_ray(origin, direction, t_max), |_, slot| {
                let instance = self.tlas.bvh.primitive_indices[slot];
                if self.any_in_instance(instance, origin, direction, t_max) {
                    0.0
                } else {
                    f32::INFINITY
                }
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

    fn closest_in_instance(
        &self,
        instance: u32,
        origin: Vec3,
        direction: Vec3,
        t_max: f32,
    ) -> Option<(f32, u32, Vec2)> {
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

/// Each instance's transforms, its mesh index checked against `mesh_count`.
pub fn instance_transforms(
    instances: &[Instance],
    mesh_count: usize,
) -> Result<Vec<InstanceTransforms>, BvhError> {
    instances
        .iter()
        .enumerate()
        .map(|(i, inst)| InstanceTransforms::new(i, inst, mesh_count))
        .collect()
}

/// obvhs's ray; `+ 0.0` turns a -0.0 direction component into +0.0 so that obvhs's octant (sign
/// test) and its reciprocal (sign bit) agree, as they do in the WGSL.
pub fn obvhs_ray(origin: Vec3, direction: Vec3, t_max: f32) -> Ray {
    Ray::new(Vec3A::from(origin), Vec3A::from(direction + Vec3::ZERO), 0.0, t_max)
}

#[cfg(test)]
mod tests {
    use glam::{Mat4, Quat};
    use obvhs::cwbvh::CwBvh;

    use super::*;
    use crate::bvh::{SplitMix64, displaced_sphere, random_rays};
    use crate::scene::{Material, Mesh};

    /// The WGSL's (7 - octant) in every byte.
    fn octant_inv4(d: Vec3) -> u32 {
        (if d.x < 0.0 { 0 } else { 0x0404_0404 })
            | (if d.y < 0.0 { 0 } else { 0x0202_0202 })
            | (if d.z < 0.0 { 0 } else { 0x0101_0101 })
    }

    /// One trip of `sg_trip`: the nearest inner child of `group` is intersected (the rest of the
    /// group pushed), or a group without inner children is returned as the primitive group.
    fn trip(
        bvh: &CwBvh,
        stack: &mut Vec<(u32, u32)>,
        deepest: &mut usize,
        group: (u32, u32),
        ray: &Ray,
        oct: u32,
    ) -> ((u32, u32), (u32, u32)) {
        let (base, mut bits) = group;
        if bits & 0xff00_0000 == 0 {
            return ((0, 0), group);
        }
        let hits_imask = bits;
        let child_bit = 31 - bits.leading_zeros();
        bits &= !(1 << child_bit);
        if bits & 0xff00_0000 != 0 {
            stack.push((base, bits));
            *deepest = (*deepest).max(stack.len());
        }
        let slot = (child_bit - 24) ^ (oct & 0xff);
        let node = &bvh.nodes[(base + (hits_imask & !(u32::MAX << slot)).count_ones()) as usize];
        let hitmask = node.intersect_ray(ray, oct);
        (
            (node.child_base_idx, (hitmask & 0xff00_0000) | u32::from(node.imask)),
            (node.primitive_base_idx, hitmask & 0x00ff_ffff),
        )
    }

    /// The most entries `sg_traverse`'s stack holds for this ray, replayed on the CPU without
    /// shortening the ray at hits (which only prunes).
    fn deepest_stack(bvh: &SceneBvh, origin: Vec3, direction: Vec3) -> usize {
        let (mut stack, mut deepest) = (Vec::new(), 0);
        let (world, oct) = (obvhs_ray(origin, direction, 1e30), octant_inv4(direction));
        let mut node_group = (0u32, 0x8000_0000u32);
        if bvh.tlas.bvh.nodes.is_empty() {
            return 0;
        }
        loop {
            let (next, mut instances) =
                trip(&bvh.tlas.bvh, &mut stack, &mut deepest, node_group, &world, oct);
            node_group = next;
            if instances.1 != 0 {
                let local = 31 - instances.1.leading_zeros();
                instances.1 &= !(1 << local);
                if instances.1 != 0 {
                    stack.push(instances);
                    deepest = deepest.max(stack.len());
                }
                let instance = bvh.tlas.bvh.primitive_indices[(instances.0 + local) as usize];
                let (blas, o, d) = bvh.object_ray(instance, origin, direction);
                let (ray, blas_oct) = (obvhs_ray(o, d, 1e30), octant_inv4(d));
                let tlas_entries = stack.len();
                let mut group = (0u32, if blas.bvh.nodes.is_empty() { 0 } else { 0x8000_0000u32 });
                while group.1 & 0xff00_0000 != 0 {
                    group = trip(&blas.bvh, &mut stack, &mut deepest, group, &ray, blas_oct).0;
                    if group.1 & 0xff00_0000 == 0 && stack.len() > tlas_entries {
                        group = stack.pop().unwrap_or_default();
                    }
                }
            }
            if node_group.1 & 0xff00_0000 == 0 {
                match stack.pop() {
                    Some(group) => node_group = group,
                    None => return deepest,
                }
            }
        }
    }

    fn scene(meshes: Vec<Mesh>, instances: Vec<Instance>) -> SceneDesc {
        SceneDesc { meshes, materials: vec![Material::default()], instances, ..Default::default() }
    }

    #[test]
    fn the_stack_bound_holds_what_the_traversal_pushes() {
        let mut rng = SplitMix64::new(9);
        // A deep BLAS over a floor; then hundreds of small instances, so that the TLAS is a few
        // levels deep and its leaf groups hold several instances each.
        let sphere = scene(
            vec![displaced_sphere(20_000, 1), Mesh::plane(4.0)],
            vec![
                Instance { mesh: 0, material: 0, transform: Mat4::IDENTITY },
                Instance {
                    mesh: 1,
                    material: 0,
                    transform: Mat4::from_translation(Vec3::new(0.0, -1.2, 0.0)),
                },
            ],
        );
        let crowd = scene(
            vec![displaced_sphere(300, 2), Mesh::plane(0.5)],
            (0..600)
                .map(|i| Instance {
                    mesh: i % 2,
                    material: 0,
                    transform: Mat4::from_scale_rotation_translation(
                        Vec3::splat(rng.range(0.05, 0.4)),
                        Quat::from_axis_angle(rng.unit_vector(), rng.range(0.0, 6.0)),
                        Vec3::new(rng.range(-5.0, 5.0), rng.range(-5.0, 5.0), rng.range(-5.0, 5.0)),
                    ),
                })
                .collect(),
        );
        for (name, desc) in [("sphere and floor", sphere), ("600 instances", crowd)] {
            let bvh = SceneBvh::new(&desc).expect("bvh");
            let bound = bvh.stack_entries() as usize;
            let deepest = random_rays(bvh.bounds(), 20_000, 1e30, 3)
                .iter()
                .map(|r| deepest_stack(&bvh, r.origin, r.direction))
                .max()
                .unwrap_or(0);
            eprintln!(
                "{name}: TLAS depth {}, bound {bound}, deepest replayed stack {deepest}",
                bvh.tlas.depth
            );
            assert!(
                deepest <= bound,
                "{name}: a ray's traversal held {deepest} entries, the bound is {bound}"
            );
            assert!(deepest > 0, "{name}: the rays push groups");
        }
    }
}
