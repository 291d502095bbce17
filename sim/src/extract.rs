//! World -> `SceneDesc`: the dynamic parts (instances, lights, camera, materials,
//! environment) are rebuilt from the ECS each frame; meshes and textures are set once.
//!
//! Output order is spawn order ([`SpawnOrder`], then entity id), fixed once the simulation
//! is set up, so the same world always gives the same `SceneDesc`.

use bevy_ecs::prelude::*;
use glam::Vec3;
use scene::{Camera as CameraDesc, Instance, Light, SceneDesc};

use crate::components::{Camera, Hidden, Intensity, LightSource, MeshInstance, SpawnOrder};
use crate::resources::{ActiveCamera, Environment, MaterialTable};
use crate::transform::GlobalTransform;

/// Places a local-space light with the entity's world matrix and scales its power.
pub fn world_light(light: &Light, global: &GlobalTransform, factor: f32) -> Light {
    let m = global.0;
    let dir = |d: Vec3| m.transform_vector3(d).normalize_or(d);
    match *light {
        Light::Directional { direction, irradiance, angular_radius } => Light::Directional {
            direction: dir(direction),
            irradiance: irradiance * factor,
            angular_radius,
        },
        Light::Point { position, intensity } => {
            Light::Point { position: m.transform_point3(position), intensity: intensity * factor }
        }
        Light::Spot { position, direction, intensity, inner_angle, outer_angle } => Light::Spot {
            position: m.transform_point3(position),
            direction: dir(direction),
            intensity: intensity * factor,
            inner_angle,
            outer_angle,
        },
    }
}

/// The camera description of a camera entity.
pub fn world_camera(camera: &Camera, global: &GlobalTransform) -> CameraDesc {
    let m = global.0;
    let position = m.transform_point3(Vec3::ZERO);
    let forward = m.transform_vector3(Vec3::NEG_Z).normalize();
    let up = m.transform_vector3(Vec3::Y).normalize();
    CameraDesc { position, target: position + forward, up, vfov: camera.vfov }
}

/// Rewrites `out`'s instances, lights, camera, materials and environment from `world`.
///
/// An emissive mesh with an [`Intensity`] gets its own copy of its material (appended after
/// the table) with the emission scaled, so flashing one lamp never dims another that shares
/// the material. The number of materials is therefore constant over a run.
pub fn extract_dynamic(world: &mut World, out: &mut SceneDesc) {
    let table = world.resource::<MaterialTable>().materials.clone();
    out.materials.clear();
    out.materials.extend_from_slice(&table);

    type Key = (Option<SpawnOrder>, Entity);
    let mut instances: Vec<(Key, Instance)> = Vec::new();
    let mut query = world.query_filtered::<(
        Entity,
        Option<&SpawnOrder>,
        &MeshInstance,
        &GlobalTransform,
        Option<&Intensity>,
    ), Without<Hidden>>();
    for (entity, order, mesh, global, intensity) in query.iter(world) {
        instances.push((
            (order.copied(), entity),
            Instance { mesh: mesh.mesh, material: mesh.material, transform: global.0 },
        ));
        if let Some(intensity) = intensity {
            let mut own = table[mesh.material as usize];
            own.emission *= intensity.factor();
            out.materials.push(own);
            instances.last_mut().unwrap().1.material = (out.materials.len() - 1) as u32;
        }
    }
    // Materials were appended in query order; renumber them in spawn order.
    instances.sort_by_key(|(k, _)| *k);
    let mut derived = Vec::new();
    for (_, instance) in instances.iter_mut() {
        if instance.material as usize >= table.len() {
            derived.push(out.materials[instance.material as usize]);
            instance.material = (table.len() + derived.len() - 1) as u32;
        }
    }
    out.materials.truncate(table.len());
    out.materials.extend(derived);
    out.instances.clear();
    out.instances.extend(instances.into_iter().map(|(_, i)| i));

    let mut lights: Vec<(Key, Light)> = world
        .query::<(Entity, Option<&SpawnOrder>, &LightSource, &GlobalTransform, Option<&Intensity>)>(
        )
        .iter(world)
        .map(|(e, o, l, g, i)| {
            ((o.copied(), e), world_light(&l.0, g, i.map_or(1.0, Intensity::factor)))
        })
        .collect();
    lights.sort_by_key(|(k, _)| *k);
    out.lights.clear();
    out.lights.extend(lights.into_iter().map(|(_, l)| l));

    out.environment = world.resource::<Environment>().0;
    let active = world.resource::<ActiveCamera>().0;
    if let (Some(camera), Some(global)) =
        (world.get::<Camera>(active), world.get::<GlobalTransform>(active))
    {
        out.camera = world_camera(camera, global);
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn lights_follow_their_entity() {
        let g = GlobalTransform(glam::Mat4::from_rotation_translation(
            glam::Quat::from_rotation_z(std::f32::consts::FRAC_PI_2),
            Vec3::new(1.0, 2.0, 3.0),
        ));
        let p = world_light(&Light::Point { position: Vec3::ZERO, intensity: Vec3::ONE }, &g, 2.0);
        assert_eq!(
            p,
            Light::Point { position: Vec3::new(1.0, 2.0, 3.0), intensity: Vec3::splat(2.0) }
        );
        let d = world_light(
            &Light::Directional { direction: Vec3::X, irradiance: Vec3::ONE, angular_radius: 0.01 },
            &g,
            1.0,
        );
        let Light::Directional { direction, .. } = d else { panic!("kind changed") };
        assert!((direction - Vec3::Y).length() < 1e-6, "{direction}");
    }
}
