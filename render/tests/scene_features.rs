//! Passes compiled for the features a scene has (render/src/scene_features.rs): the same images
//! as passes compiled for every feature and the largest traversal stack, and compiled again when
//! the scene gains a feature.

mod common;

use common::{H, W, gpu, room_scene};
use glam::{Mat4, Vec3};
use render::compute::BufferBinding;
use render::path_tracer::{PathTracer, PathTracerSettings};
use render::scene::{Instance, Light, SceneDesc, Texture};
use render::scene_features::SceneFeatures;
use render::scene_gpu::SceneGpu;
use render::taa::Taa;

fn settings() -> PathTracerSettings {
    PathTracerSettings { width: W, height: H, max_depth: 4, rr_start_depth: 2 }
}

/// The room without its walls: the red box under the panel, open to the environment.
fn open_scene() -> SceneDesc {
    let mut scene = room_scene();
    scene.instances.remove(0);
    scene
}

/// [`open_scene`] with an environment, a point light and a checker texture on the box.
fn lit_open_scene() -> SceneDesc {
    let mut scene = open_scene();
    scene.environment = Vec3::splat(0.3);
    scene
        .lights
        .push(Light::Point { position: Vec3::new(1.0, 1.0, 1.0), intensity: Vec3::splat(2.0) });
    let (dark, light) = ([40u8, 40, 40, 255], [220u8, 220, 220, 255]);
    scene.textures.push(Texture {
        name: "checker".into(),
        width: 2,
        height: 2,
        rgba8: [dark, light, light, dark].concat(),
    });
    scene.materials[1].base_color_texture = Some(0);
    scene
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
        traversal_stack: stack,
    };
    assert_eq!(
        sg.library().features(),
        room,
        "the room has only its emissive panel, and no textures"
    );
    let own = tracer.render(gpu(), &sg, 4, 7, 0).expect("frame");
    sg.library().specialise(gpu(), &sg, SceneFeatures::ALL).expect("compile for every feature");
    assert_eq!(sg.library().features(), SceneFeatures::ALL);
    let every = tracer.render(gpu(), &sg, 4, 7, 0).expect("frame");
    assert!(own.radiance.iter().any(|p| p[0] > 0.0), "the room is lit");
    assert_eq!(
        own.radiance, every.radiance,
        "the estimators of absent lights draw no random numbers and add nothing, and the stack holds what the BVH needs"
    );
}

#[test]
fn a_scene_that_gains_features_gets_passes_compiled_for_them() {
    let mut sg = SceneGpu::new(gpu(), &open_scene(), settings()).expect("scene");
    let mut tracer = PathTracer::new(gpu(), &sg).expect("tracer");
    // Any pass on the library: TAA's trace pass, as a method holds it.
    let own = [
        BufferBinding::uniform("taa", "TaaParams"),
        BufferBinding::read_write("taa_current", "array<vec4f>"),
        BufferBinding::read_write("taa_primary", "array<TaaPrimary>"),
        BufferBinding::read_write("taa_counters", "array<atomic<u32>>"),
    ];
    let (_, [before]) = sg
        .library_pass(gpu(), "taa_trace.wgsl", Taa::trace_program(), &own, ["taa_trace"])
        .expect("pass");
    let held = before.get();
    let dark = tracer.render(gpu(), &sg, 4, 7, 0).expect("frame");

    sg.try_update(gpu(), &lit_open_scene()).expect("update");
    let stack = SceneFeatures::stack_for(sg.geometry().stack_entries());
    assert_eq!(
        sg.library().features(),
        SceneFeatures { traversal_stack: stack, ..SceneFeatures::ALL }
    );
    assert!(
        before.get() != held,
        "the held pipeline was swapped for one compiled with the new features"
    );
    let updated = tracer.render(gpu(), &sg, 4, 7, 0).expect("frame");
    // A scene uploaded lit from the start: its passes were compiled for its features.
    let lit = SceneGpu::new(gpu(), &lit_open_scene(), settings()).expect("scene");
    let fresh =
        PathTracer::new(gpu(), &lit).expect("tracer").render(gpu(), &lit, 4, 7, 0).expect("frame");
    assert_eq!(
        updated.radiance, fresh.radiance,
        "after the update the passes sample the environment and the point light, and read the texture"
    );
    assert!(updated.radiance != dark.radiance);
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
