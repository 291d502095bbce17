//! The subsurface test scene (realtime-sss-thesis.txt): a head-sized "skin" sphere
//! on a floor under a point light "lamp", a bar casting a hard shadow edge across it (where
//! scattering shows), two dim "candle" lights, and a hidden "bird" prototype for boids. The
//! skin is a plain diffuse material here; a scenario makes it subsurface with a material
//! override (`materials: [(material: "skin", subsurface: (dmfp: ...))]`).

use glam::{Quat, Vec3};
use scene::{Light, Material};

use super::courtyard::bird_mesh;
use super::geometry::{MeshBuilder, unit_cube, unit_quad};
use crate::template::WorldTemplate;
use crate::transform::Transform;

pub const RADIUS: f32 = 0.5;

pub fn build() -> WorldTemplate {
    let mut t = WorldTemplate { environment: Vec3::splat(0.02), ..Default::default() };
    let mut b = MeshBuilder::new("sphere");
    b.sphere(RADIUS, 48, 24);
    let sphere = t.add_mesh(b.build());
    let quad = t.add_mesh(unit_quad("quad"));
    let cube = t.add_mesh(unit_cube("cube"));
    let bird = t.add_mesh(bird_mesh());
    let floor = t.add_material(
        "floor",
        Material { base_color: Vec3::splat(0.5), specular: 0.0, ..Default::default() },
    );
    // Albedo of light skin; no specular lobe, so the path tracer's radiance over the base
    // colour is the demodulated diffuse irradiance.
    let skin = t.add_material(
        "skin",
        Material { base_color: Vec3::new(0.85, 0.6, 0.5), specular: 0.0, ..Default::default() },
    );
    let dark = t.add_material(
        "dark",
        Material { base_color: Vec3::splat(0.1), specular: 0.0, ..Default::default() },
    );

    t.add_object(
        "floor",
        quad,
        floor,
        Transform::from_trs(Vec3::ZERO, Quat::IDENTITY, Vec3::new(6.0, 1.0, 6.0)),
    );
    t.add_object("head", sphere, skin, Transform::from_translation(Vec3::new(0.0, RADIUS, 0.0)));
    // A thin vertical bar between the lamp and the sphere: a hard shadow edge on the skin.
    t.add_object(
        "bar",
        cube,
        dark,
        Transform::from_trs(Vec3::new(0.35, 0.9, 0.55), Quat::IDENTITY, Vec3::new(0.06, 1.8, 0.06)),
    );
    t.add_object("bird", bird, dark, Transform::from_translation(Vec3::new(0.0, 1.6, 0.0)));

    t.add_light(
        "lamp",
        Light::Point { position: Vec3::new(1.0, 1.8, 1.6), intensity: Vec3::splat(6.0) },
    );
    t.add_light(
        "candle_left",
        Light::Point { position: Vec3::new(-0.9, 0.3, 0.6), intensity: Vec3::new(0.5, 0.3, 0.1) },
    );
    t.add_light(
        "candle_right",
        Light::Point { position: Vec3::new(0.9, 0.3, -0.2), intensity: Vec3::new(0.5, 0.3, 0.1) },
    );
    t.add_camera("camera", Vec3::new(0.0, 0.75, 1.9), Vec3::new(0.0, 0.5, 0.0), 40.0);
    t
}
