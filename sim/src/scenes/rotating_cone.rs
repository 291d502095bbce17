//! A cone lying on its side on a floor, on a turntable: rotating `cone` about +Y sweeps
//! its shadow and silhouette.

use glam::{Quat, Vec3};
use scene::{Light, Material};

use super::geometry::{MeshBuilder, unit_quad};
use crate::components::MeshInstance;
use crate::template::{NodeTemplate, WorldTemplate};
use crate::transform::Transform;

pub const RADIUS: f32 = 0.4;
pub const HEIGHT: f32 = 1.2;

pub fn build() -> WorldTemplate {
    let mut t = WorldTemplate { environment: Vec3::splat(0.05), ..Default::default() };
    let mut b = MeshBuilder::new("cone");
    b.cone(RADIUS, HEIGHT, 48);
    let cone = t.add_mesh(b.build());
    let quad = t.add_mesh(unit_quad("quad"));
    let floor =
        t.add_material("floor", Material { base_color: Vec3::splat(0.7), ..Default::default() });
    let paint = t.add_material(
        "paint",
        Material { base_color: Vec3::new(0.8, 0.25, 0.1), roughness: 0.35, ..Default::default() },
    );

    t.add_object(
        "floor",
        quad,
        floor,
        Transform::from_trs(Vec3::ZERO, Quat::IDENTITY, Vec3::new(6.0, 1.0, 6.0)),
    );
    // Turntable pivot at the origin; the body is laid down on one side line: turning the
    // +Y axis by -(90° + half-angle) about Z makes the line from the +X rim point to the apex
    // horizontal and lowest. Then it is lifted onto the floor and centred on the pivot.
    let cone_mesh = t.meshes[cone as usize].clone();
    let pivot = t.add_node(NodeTemplate::new("cone", Transform::IDENTITY));
    let half_angle = (RADIUS / HEIGHT).atan();
    let tilt = Quat::from_rotation_z(-(std::f32::consts::FRAC_PI_2 + half_angle));
    let lift = -cone_mesh.positions.iter().map(|p| (tilt * *p).y).fold(f32::MAX, f32::min);
    let middle = tilt * Vec3::new(0.0, 0.5 * HEIGHT, 0.0);
    let mut body = NodeTemplate::new(
        "cone_body",
        Transform::from_trs(Vec3::new(-middle.x, lift, -middle.z), tilt, Vec3::ONE),
    );
    body.parent = Some(pivot);
    body.mesh = Some(MeshInstance { mesh: cone, material: paint });
    t.add_node(body);

    t.add_light(
        "lamp",
        Light::Point { position: Vec3::new(1.0, 2.5, 1.5), intensity: Vec3::splat(8.0) },
    );
    t.add_camera("camera", Vec3::new(0.0, 1.6, 3.0), Vec3::new(0.0, 0.3, 0.0), 45.0);
    t
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn cone_rests_on_the_floor() {
        let t = build();
        let body = t.nodes.iter().find(|n| n.name == "cone_body").unwrap();
        let m = body.transform.matrix();
        let lowest =
            t.meshes[0].positions.iter().map(|p| m.transform_point3(*p).y).fold(f32::MAX, f32::min);
        assert!(lowest.abs() < 1e-4, "lowest point at y = {lowest}");
        // It lies on a side line: the apex touches the floor too.
        let apex = m.transform_point3(Vec3::new(0.0, HEIGHT, 0.0)).y;
        assert!(apex.abs() < 1e-4, "apex at y = {apex}");
    }
}
