//! Passes compiled for the features a scene has (render/src/scene_features.rs): the same images
//! as passes compiled for every feature and the largest traversal stack, and compiled again when
//! the scene gains a feature (a held pass recompiled: methods/taa/tests/scene_features.rs).

use testkit::test_scenes as common;

use common::{H, W, gpu, room_scene};
use glam::{Mat4, Vec3};
use render::path_tracer::{PathTracer, PathTracerSettings};
use render::scene::Instance;
use render::scene_features::SceneFeatures;
use render::scene_gpu::SceneGpu;

fn settings() -> PathTracerSettings {
    PathTracerSettings { width: W, height: H, max_depth: 4, rr_start_depth: 2 }
}

#[test]
fn passes_for_the_scene_s_lights_render_what_passes_for_every_light_do() {
    let sg = SceneGpu::new(gpu(), &room_scene(), settings()).expect("scene");
    let mut tracer = PathTracer::new(gpu(), &sg).expect("tracer");
    let stack = SceneFeatures::stack_for(sg.geometry().stack_entries());
    assert!(
        stack < SceneFeatures::ALL.traversal_stack,
        "the room's BVH is shallow: {stack} entries"
    );
    let room = SceneFeatures {
        analytic_lights: false,
        emitters: true,
        environment: false,
        textures: false,
        specular: false,
        traversal_stack: stack,
    };
    assert_eq!(
        sg.library().features(),
        room,
        "the room has only its emissive panel, no textures and Lambertian materials"
    );
    let own = tracer.render(gpu(), &sg, 4, 7, 0).expect("frame");
    sg.library()
        .specialise(gpu(), sg.library_groups(), SceneFeatures::ALL)
        .expect("compile for every feature");
    assert_eq!(sg.library().features(), SceneFeatures::ALL);
    let every = tracer.render(gpu(), &sg, 4, 7, 0).expect("frame");
    assert!(own.radiance.iter().any(|p| p[0] > 0.0), "the room is lit");
    assert_eq!(
        own.radiance, every.radiance,
        "the estimators of absent lights draw no random numbers and add nothing, the Lambertian BSDF's shortcut gives the general formulas' values, and the stack holds what the BVH needs"
    );
}

#[test]
fn the_traversal_stack_never_shrinks_within_a_run() {
    // 64 boxes in a row: a TLAS some levels deep; then the room's three instances.
    let mut crowd = room_scene();
    crowd.instances = (0..64)
        .map(|i| Instance {
            mesh: 1,
            material: 1,
            transform: Mat4::from_translation(Vec3::new(i as f32 * 3.0, 0.0, -4.0)),
        })
        .collect();
    let mut sg = SceneGpu::new(gpu(), &crowd, settings()).expect("scene");
    let mut tracer = PathTracer::new(gpu(), &sg).expect("tracer");
    let deep = sg.geometry().stack_entries();
    assert_eq!(sg.library().features().traversal_stack, SceneFeatures::stack_for(deep));
    sg.try_update(gpu(), &room_scene()).expect("update");
    assert!(
        sg.geometry().stack_entries() < deep,
        "fewer instances, a shallower TLAS: {} against {deep}",
        sg.geometry().stack_entries()
    );
    assert_eq!(
        sg.library().features().traversal_stack,
        SceneFeatures::stack_for(deep),
        "kept: a TLAS that deepens again needs no new pipelines"
    );
    let frame = tracer.render(gpu(), &sg, 1, 7, 0).expect("frame");
    assert!(frame.radiance.iter().any(|p| p[0] > 0.0));
}

/// A glossy box (material 1, specular factor 1) keeps the general BSDF: its passes render what
/// passes compiled for every feature do, and not the image of the same room with a Lambertian
/// box, which the shortcut for scenes without specular lobes (pt_bsdf.wgsl) would give.
#[test]
fn a_scene_with_a_specular_lobe_keeps_the_general_bsdf() {
    let mut glossy = room_scene();
    glossy.materials[1].specular = 1.0;
    let sg = SceneGpu::new(gpu(), &glossy, settings()).expect("scene");
    let mut tracer = PathTracer::new(gpu(), &sg).expect("tracer");
    let own = tracer.render(gpu(), &sg, 4, 7, 0).expect("frame");
    let lambertian = SceneGpu::new(gpu(), &room_scene(), settings()).expect("scene");
    let matte = PathTracer::new(gpu(), &lambertian)
        .expect("tracer")
        .render(gpu(), &lambertian, 4, 7, 0)
        .expect("frame");
    assert!(own.radiance != matte.radiance, "the glossy box reflects differently");
    sg.library()
        .specialise(gpu(), sg.library_groups(), SceneFeatures::ALL)
        .expect("compile for every feature");
    let every = tracer.render(gpu(), &sg, 4, 7, 0).expect("frame");
    assert_eq!(own.radiance, every.radiance, "the scene's passes evaluate the specular lobe");
}
