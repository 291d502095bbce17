//! An open courtyard: buildings around a square, a colonnade, a lantern and a bird (the
//! prototype of the boids scenario), under a dominant sun and a dim sky.

use glam::{Quat, Vec2, Vec3};
use scene::{Light, Material};

use super::geometry::{MeshBuilder, unit_cube, unit_quad};
use crate::template::WorldTemplate;
use crate::transform::Transform;

/// Sun elevation above the horizon, degrees; the sun shines from the south-west.
pub const SUN_ELEVATION: f32 = 40.0;

/// A small arrow-shaped "bird" pointing along -Z (boids turn -Z into their heading).
pub(crate) fn bird_mesh() -> scene::Mesh {
    let mut b = MeshBuilder::new("bird");
    let nose = Vec3::new(0.0, 0.0, -0.15);
    let tail = [Vec3::new(-0.12, 0.0, 0.1), Vec3::new(0.12, 0.0, 0.1), Vec3::new(0.0, 0.05, 0.08)];
    let v = |b: &mut MeshBuilder, p: Vec3| b.vertex(p, p.normalize_or(Vec3::Y), Vec2::ZERO);
    let n = v(&mut b, nose);
    let t: Vec<u32> = tail.iter().map(|p| v(&mut b, *p)).collect();
    let center = (nose + tail[0] + tail[1] + tail[2]) / 4.0;
    let faces = [(n, t[0], t[2]), (n, t[2], t[1]), (n, t[1], t[0]), (t[0], t[1], t[2])];
    for (a, c, d) in faces {
        let pos = |i: u32| [nose, tail[0], tail[1], tail[2]][i as usize];
        let outward = (pos(a) + pos(c) + pos(d)) / 3.0 - center;
        b.triangle(a, c, d, outward);
    }
    b.build()
}

pub fn build() -> WorldTemplate {
    let mut t = WorldTemplate { environment: Vec3::new(0.25, 0.32, 0.45), ..Default::default() };
    let quad = t.add_mesh(unit_quad("quad"));
    let cube = t.add_mesh(unit_cube("cube"));
    let bird = t.add_mesh(bird_mesh());
    let paving = t.add_material(
        "paving",
        Material { base_color: Vec3::new(0.55, 0.52, 0.48), ..Default::default() },
    );
    let walls = t.add_material(
        "walls",
        Material { base_color: Vec3::new(0.8, 0.7, 0.55), ..Default::default() },
    );
    let stone = t.add_material(
        "stone",
        Material { base_color: Vec3::splat(0.65), roughness: 0.4, ..Default::default() },
    );
    let feathers = t.add_material(
        "feathers",
        Material { base_color: Vec3::new(0.15, 0.15, 0.18), ..Default::default() },
    );

    t.add_object(
        "ground",
        quad,
        paving,
        Transform::from_trs(Vec3::ZERO, Quat::IDENTITY, Vec3::new(30.0, 1.0, 30.0)),
    );
    // Four buildings leave the corners open so the sun reaches in at low angles.
    let building =
        |c: Vec3, s: Vec3| Transform::from_trs(c + Vec3::Y * (0.5 * s.y), Quat::IDENTITY, s);
    t.add_object(
        "building_north",
        cube,
        walls,
        building(Vec3::new(0.0, 0.0, -7.0), Vec3::new(10.0, 6.0, 3.0)),
    );
    t.add_object(
        "building_south",
        cube,
        walls,
        building(Vec3::new(0.0, 0.0, 7.0), Vec3::new(10.0, 4.0, 3.0)),
    );
    t.add_object(
        "building_east",
        cube,
        walls,
        building(Vec3::new(7.0, 0.0, 0.0), Vec3::new(3.0, 8.0, 9.0)),
    );
    t.add_object(
        "building_west",
        cube,
        walls,
        building(Vec3::new(-7.0, 0.0, 0.0), Vec3::new(3.0, 5.0, 9.0)),
    );
    for i in 0..8 {
        let x = -3.5 + i as f32;
        t.add_object(
            &format!("pillar_{i}"),
            cube,
            stone,
            Transform::from_trs(Vec3::new(x, 1.5, -3.5), Quat::IDENTITY, Vec3::new(0.3, 3.0, 0.3)),
        );
    }
    t.add_object("bird", bird, feathers, Transform::from_translation(Vec3::new(0.0, 2.0, 0.0)));

    let (el, az) = (SUN_ELEVATION.to_radians(), 225f32.to_radians());
    let to_sun = Vec3::new(el.cos() * az.cos(), el.sin(), el.cos() * az.sin());
    t.add_light(
        "sun",
        Light::Directional {
            direction: -to_sun,
            irradiance: Vec3::new(3.0, 2.8, 2.5),
            angular_radius: 0.0047,
        },
    );
    t.add_light(
        "lamp",
        Light::Point { position: Vec3::new(2.0, 2.5, 2.0), intensity: Vec3::new(4.0, 3.0, 1.5) },
    );
    t.add_camera("camera", Vec3::new(0.0, 3.0, 5.0), Vec3::new(0.0, 1.0, -2.0), 65.0);
    t
}
