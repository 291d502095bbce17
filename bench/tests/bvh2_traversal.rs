//! The WGSL BVH2 traversal (bvh2_traversal.wgsl) against obvhs's BVH2 traversal, itself checked
//! against brute force, on the render crate's traversal scenes and rays.

#[path = "../../render/tests/traversal_common/mod.rs"]
mod traversal_common;

use bench::{Bvh2Geometry, Bvh2Traversal, SceneBvh2};
use glam::{Mat4, Quat, Vec3};
use render::bvh::SceneGeometry;
use render::scene::{Instance, SceneDesc};
use traversal_common::*;

reference!(SceneBvh2);

/// The WGSL BVH2 traversal against obvhs's BVH2 traversal (itself against brute force) on the
/// traversal tests' scenes and rays (the same seeds): the glTF torus, the hairball, instances
/// with rotations, mirroring and an empty mesh.
#[test]
fn bvh2_gpu_traversal_matches_obvhs_bvh2_and_brute_force() {
    let gpu = gpu();
    let tmp = tempfile::tempdir().unwrap();
    let dir = tmp.path().to_path_buf();
    let path = write_gltf(
        &dir,
        &torus(1.0, 0.35, 48, 24),
        Quat::from_rotation_x(0.7) * Quat::from_rotation_z(0.3),
        Vec3::new(1.5, 0.6, 1.0),
        Vec3::new(0.2, -0.1, 0.3),
    );
    let gltf = load_gltf(&path);
    drop(tmp);
    let hairball = SceneDesc {
        meshes: vec![hairball(400, 8, 0.006, 2)],
        instances: vec![Instance { mesh: 0, material: 0, transform: Mat4::IDENTITY }],
        ..Default::default()
    };
    let scenes = [
        ("BVH2 glTF torus", gltf, 1),
        ("BVH2 hairball", hairball, 2),
        ("BVH2 instances", instanced_scene(3), 3),
    ];
    for (label, scene, seed) in scenes {
        let geometry = SceneGeometry::new(&gpu, &scene).unwrap();
        let bvh2 = Bvh2Geometry::new(&gpu, &scene, &geometry).unwrap();
        let rays = rays_for(&scene, geometry.cpu(), seed);
        cpu_matches_brute_force(label, &scene, bvh2.cpu(), &rays[..RAYS / 3]);
        let traversal = Bvh2Traversal { geometry: &geometry, bvh2: &bvh2 };
        let batch = traversal.batch(&gpu);
        let hits = batch.trace_closest(&gpu, &traversal, &rays).unwrap();
        let any = batch.trace_any(&gpu, &traversal, &rays).unwrap();
        check(label, &compare(label, &scene, bvh2.cpu(), &rays, &hits, &any));
    }
}
