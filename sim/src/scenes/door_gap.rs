//! Two rooms sharing a wall with a doorway; the door on its hinge is nearly closed, so the
//! dark room (camera) is lit only through a narrow gap by a lamp in the other room.

use glam::{Quat, Vec3};
use scene::{Light, Material};

use super::geometry::unit_cube;
use crate::template::{NodeTemplate, WorldTemplate};
use crate::transform::Transform;

/// Opening angle of the door in degrees.
pub const DOOR_ANGLE: f32 = 6.0;

fn slab(min: Vec3, max: Vec3) -> Transform {
    Transform::from_trs(0.5 * (min + max), Quat::IDENTITY, max - min)
}

pub fn build() -> WorldTemplate {
    let mut t = WorldTemplate::default();
    let cube = t.add_mesh(unit_cube("cube"));
    let wall =
        t.add_material("wall", Material { base_color: Vec3::splat(0.75), ..Default::default() });
    let floor = t.add_material(
        "floor",
        Material { base_color: Vec3::new(0.6, 0.5, 0.4), roughness: 0.6, ..Default::default() },
    );
    let wood = t.add_material(
        "wood",
        Material { base_color: Vec3::new(0.45, 0.3, 0.2), roughness: 0.5, ..Default::default() },
    );

    // Rooms: dark x in [-4, 0], lit x in [0, 3]; z in [-2, 2]; y in [0, 2.5]. Walls 0.1 thick.
    let (wt, y1) = (0.1, 2.5);
    t.add_object("floor", cube, floor, slab(Vec3::new(-4.1, -wt, -2.1), Vec3::new(3.1, 0.0, 2.1)));
    t.add_object(
        "ceiling",
        cube,
        wall,
        slab(Vec3::new(-4.1, y1, -2.1), Vec3::new(3.1, y1 + wt, 2.1)),
    );
    t.add_object(
        "wall_west",
        cube,
        wall,
        slab(Vec3::new(-4.1, 0.0, -2.1), Vec3::new(-4.0, y1, 2.1)),
    );
    t.add_object("wall_east", cube, wall, slab(Vec3::new(3.0, 0.0, -2.1), Vec3::new(3.1, y1, 2.1)));
    t.add_object(
        "wall_north",
        cube,
        wall,
        slab(Vec3::new(-4.1, 0.0, -2.1), Vec3::new(3.1, y1, -2.0)),
    );
    t.add_object(
        "wall_south",
        cube,
        wall,
        slab(Vec3::new(-4.1, 0.0, 2.0), Vec3::new(3.1, y1, 2.1)),
    );
    // The dividing wall at x = 0 with a doorway z in [-0.45, 0.45], y in [0, 2].
    let (d0, d1, dh) = (-0.45, 0.45, 2.0);
    t.add_object(
        "divider_left",
        cube,
        wall,
        slab(Vec3::new(-0.05, 0.0, -2.0), Vec3::new(0.05, y1, d0)),
    );
    t.add_object(
        "divider_right",
        cube,
        wall,
        slab(Vec3::new(-0.05, 0.0, d1), Vec3::new(0.05, y1, 2.0)),
    );
    t.add_object("lintel", cube, wall, slab(Vec3::new(-0.05, dh, d0), Vec3::new(0.05, y1, d1)));

    // Hinge at the doorway's left jamb; the door is its child so rotating the hinge swings it.
    let hinge = t.add_node(NodeTemplate::new(
        "door_hinge",
        Transform::from_trs(
            Vec3::new(-0.05, 0.0, d0),
            Quat::from_rotation_y(DOOR_ANGLE.to_radians()),
            Vec3::ONE,
        ),
    ));
    let width = d1 - d0 - 0.01;
    let mut door = NodeTemplate::new(
        "door",
        Transform::from_trs(
            Vec3::new(-0.02, 0.5 * dh - 0.005, 0.5 * width),
            Quat::IDENTITY,
            Vec3::new(0.04, dh - 0.01, width),
        ),
    );
    door.parent = Some(hinge);
    door.mesh = Some(crate::components::MeshInstance { mesh: cube, material: wood });
    t.add_node(door);

    t.add_light(
        "lamp",
        Light::Point { position: Vec3::new(1.5, 2.0, 0.8), intensity: Vec3::new(40.0, 36.0, 30.0) },
    );
    t.add_camera("camera", Vec3::new(-3.6, 1.5, 1.6), Vec3::new(0.0, 0.7, -0.2), 55.0);
    t
}
