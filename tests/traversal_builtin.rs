//! WGSL traversal against obvhs's CPU traversal on the project's own scenes: the built-in
//! hairball (thin geometry, deep BVH) and the glTF scenario asset loaded by sim's importer.
//! (render/tests/traversal.rs covers the same on generated meshes, mirrored instances and
//! surface points; render cannot depend on sim, so the built-in scenes are tested here.)

use std::path::Path;

use render::bvh::{RayBatch, SceneGeometry, random_rays};
use render::gpu::Gpu;
use render::scene::SceneDesc;
use sim::{Scenario, Simulation};

fn scene_of(scenario: &Path) -> SceneDesc {
    let scenario = Scenario::load(scenario).expect("scenario");
    Simulation::new(&scenario).expect("scene").scene().clone()
}

/// Same instance and primitive, or a tie: both hit at the same distance (shared edges, coplanar
/// faces), where either answer is right.
fn assert_same_hits(label: &str, scene: &SceneDesc) {
    let gpu = Gpu::new().expect("a wgpu adapter (lavapipe on CI)");
    let geometry = SceneGeometry::new(&gpu, scene).unwrap();
    let rays = random_rays(geometry.bounds(), 8192, 1e30, 11);
    let batch = RayBatch::new(&gpu, &geometry);
    let closest = batch.trace_closest(&gpu, &geometry, &rays).unwrap();
    let any = batch.trace_any(&gpu, &geometry, &rays).unwrap();
    let cpu = geometry.cpu();
    let (mut hits, mut ties) = (0, 0);
    for (i, ray) in rays.iter().enumerate() {
        let c = cpu.trace_closest(ray.origin, ray.direction, ray.t_max);
        let g = closest[i];
        assert_eq!(g.is_hit(), c.is_hit(), "{label} ray {i}: GPU {g:?}, CPU {c:?}");
        assert_eq!(any[i], c.is_hit(), "{label} ray {i}: any-hit {} but CPU closest {c:?}", any[i]);
        if !c.is_hit() {
            continue;
        }
        hits += 1;
        if (g.instance, g.primitive) != (c.instance, c.primitive) {
            let tie = (g.t - c.t).abs() <= 1e-5 * c.t.abs().max(1e-3);
            assert!(tie, "{label} ray {i}: GPU {g:?}, CPU {c:?}");
            ties += 1;
        }
        assert!(
            (g.t - c.t).abs() <= 1e-4 * c.t.abs().max(1e-3),
            "{label} ray {i}: t {} vs {}",
            g.t,
            c.t
        );
    }
    eprintln!("{label}: {hits} of {} rays hit, {ties} ties", rays.len());
    assert!(hits > rays.len() / 20, "{label}: too few hits ({hits}) for a meaningful comparison");
    assert!(ties * 100 <= hits, "{label}: {ties} ties in {hits} hits");
}

#[test]
fn builtin_hairball_gpu_traversal_matches_obvhs() {
    assert_same_hits("hairball", &scene_of(Path::new("scenarios/hairball.ron")));
}

#[test]
fn gltf_scenario_gpu_traversal_matches_obvhs() {
    assert_same_hits("gltf test scene", &scene_of(Path::new("scenarios/gltf_test_scene.ron")));
}
