//! A hairball: a few thousand thin curly strands (triangular tubes) around a sphere, a
//! stress test for traversal of thin, overlapping geometry.

use glam::Vec3;
use scene::{Light, Material};

use super::geometry::{MeshBuilder, unit_quad};
use crate::rng::Rng;
use crate::template::WorldTemplate;
use crate::transform::Transform;

pub const STRANDS: u32 = 1500;
pub const SEGMENTS: u32 = 4;
/// Geometry seed: the hairball is the same whatever the scenario's seed.
const GEOMETRY_SEED: u64 = 0x4a11_ba11;

pub fn build() -> WorldTemplate {
    let mut rng = Rng::seeded(GEOMETRY_SEED);
    let mut b = MeshBuilder::new("hairball");
    for _ in 0..STRANDS {
        // Start on an inner sphere, wander outwards with a curl.
        let mut dir = rng.unit_vector();
        let mut p = dir * rng.range(0.3, 0.6);
        let mut points = vec![p];
        for _ in 0..SEGMENTS {
            dir = (dir + 0.8 * rng.unit_vector()).normalize();
            p += dir * 0.12;
            // Keep inside the ball.
            if p.length() > 0.9 {
                p *= 0.9 / p.length();
            }
            points.push(p);
        }
        b.strand(&points, 0.004);
    }
    let mut t = WorldTemplate { environment: Vec3::splat(0.6), ..Default::default() };
    let hair = t.add_mesh(b.build());
    let quad = t.add_mesh(unit_quad("quad"));
    let fibre = t.add_material(
        "fibre",
        Material { base_color: Vec3::new(0.8, 0.6, 0.35), roughness: 0.5, ..Default::default() },
    );
    let floor =
        t.add_material("floor", Material { base_color: Vec3::splat(0.5), ..Default::default() });
    t.add_object("hairball", hair, fibre, Transform::from_translation(Vec3::new(0.0, 1.0, 0.0)));
    t.add_object(
        "floor",
        quad,
        floor,
        Transform::from_trs(Vec3::ZERO, glam::Quat::IDENTITY, Vec3::new(8.0, 1.0, 8.0)),
    );
    t.add_light(
        "key",
        Light::Directional {
            direction: Vec3::new(-0.4, -1.0, -0.3).normalize(),
            irradiance: Vec3::splat(2.0),
            angular_radius: 0.02,
        },
    );
    t.add_camera("camera", Vec3::new(0.0, 1.3, 3.2), Vec3::new(0.0, 1.0, 0.0), 40.0);
    t
}

#[cfg(test)]
mod tests {
    #[test]
    fn hairball_is_tens_of_thousands_of_thin_triangles() {
        let t = super::build();
        let tris = t.meshes[0].indices.len();
        assert_eq!(tris as u32, super::STRANDS * super::SEGMENTS * 6);
        assert!((10_000..=60_000).contains(&tris), "{tris} triangles");
    }
}
