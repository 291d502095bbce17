//! A pass a method holds is compiled again when the scene gains a feature: TAA's trace pass on
//! the scene's library, before and after the scene gains lights, a texture and a glossy material.

use render::compute::BufferBinding;
use render::path_tracer::{PathTracer, PathTracerSettings};
use render::scene_features::SceneFeatures;
use render::scene_gpu::SceneGpu;
use taa::Taa;
use testkit::test_scenes::{H, W, gpu, lit_open_scene, open_scene};

fn settings() -> PathTracerSettings {
    PathTracerSettings { width: W, height: H, max_depth: 4, rr_start_depth: 2 }
}

#[test]
fn a_scene_that_gains_features_gets_passes_compiled_for_them() {
    let mut sg = SceneGpu::new(gpu(), &open_scene(), settings()).expect("scene");
    let mut tracer = PathTracer::new(gpu(), &sg).expect("tracer");
    // Any pass on the library: TAA's trace pass, as a method holds it.
    let own = [
        BufferBinding::read("taa", "TaaParams"),
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
        "after the update the passes sample the environment and the point light, read the texture and evaluate the specular lobe"
    );
    assert!(updated.radiance != dark.radiance);
}
