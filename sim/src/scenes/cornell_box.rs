//! The Cornell box (after the Cornell program of computer graphics' measured scene), in a
//! 2 m cube open towards the camera at +Z.

use glam::{Quat, Vec3};
use scene::Material;

use super::geometry::{unit_cube, unit_quad};
use crate::template::WorldTemplate;
use crate::transform::Transform;

fn diffuse(r: f32, g: f32, b: f32) -> Material {
    Material { base_color: Vec3::new(r, g, b), ..Default::default() }
}

/// A unit quad (facing +Y) turned to face `normal`, centred at `center`, `w` x `h` metres.
pub fn wall(center: Vec3, normal: Vec3, w: f32, h: f32) -> Transform {
    Transform::from_trs(center, Quat::from_rotation_arc(Vec3::Y, normal), Vec3::new(w, 1.0, h))
}

pub fn build() -> WorldTemplate {
    let mut t = WorldTemplate::default();
    let quad = t.add_mesh(unit_quad("quad"));
    let cube = t.add_mesh(unit_cube("cube"));
    let white = t.add_material("white", diffuse(0.73, 0.73, 0.73));
    let red = t.add_material("red", diffuse(0.65, 0.05, 0.05));
    let green = t.add_material("green", diffuse(0.12, 0.45, 0.15));
    let light = t.add_material(
        "light",
        Material {
            base_color: Vec3::splat(0.78),
            emission: Vec3::new(17.0, 12.0, 4.0),
            ..Default::default()
        },
    );

    t.add_object("floor", quad, white, wall(Vec3::ZERO, Vec3::Y, 2.0, 2.0));
    t.add_object("ceiling", quad, white, wall(Vec3::new(0.0, 2.0, 0.0), Vec3::NEG_Y, 2.0, 2.0));
    t.add_object("back_wall", quad, white, wall(Vec3::new(0.0, 1.0, -1.0), Vec3::Z, 2.0, 2.0));
    t.add_object("left_wall", quad, red, wall(Vec3::new(-1.0, 1.0, 0.0), Vec3::X, 2.0, 2.0));
    t.add_object("right_wall", quad, green, wall(Vec3::new(1.0, 1.0, 0.0), Vec3::NEG_X, 2.0, 2.0));
    t.add_object(
        "ceiling_light",
        quad,
        light,
        wall(Vec3::new(0.0, 1.995, 0.0), Vec3::NEG_Y, 0.5, 0.4),
    );
    t.add_object(
        "tall_box",
        cube,
        white,
        Transform::from_trs(
            Vec3::new(-0.33, 0.6, -0.3),
            Quat::from_rotation_y(17f32.to_radians()),
            Vec3::new(0.6, 1.2, 0.6),
        ),
    );
    t.add_object(
        "short_box",
        cube,
        white,
        Transform::from_trs(
            Vec3::new(0.35, 0.3, 0.3),
            Quat::from_rotation_y(-17f32.to_radians()),
            Vec3::splat(0.6),
        ),
    );
    t.add_camera("camera", Vec3::new(0.0, 1.0, 3.9), Vec3::new(0.0, 1.0, 0.0), 38.0);
    t
}
