//! The wavefront form of reference path tracing (bench/src/wavefront.rs) against the
//! megakernel: same samples, same random numbers, same order of sums, so the same image when
//! both run the same batches.

use testkit::test_scenes as common;

use bench::wavefront::Wavefront;
use common::{H, W, gpu, room_scene};
use glam::Vec3;
use render::path_tracer::{PathTracer, PathTracerSettings};
use render::scene::{Light, SceneDesc, Texture};
use render::scene_features::SceneFeatures;
use render::scene_gpu::SceneGpu;

fn settings() -> PathTracerSettings {
    PathTracerSettings { width: W, height: H, max_depth: 6, rr_start_depth: 2 }
}

/// The room without its walls, with every kind of light (two point lights, the environment, the
/// emissive panel) and a textured box.
fn lit_room() -> SceneDesc {
    let mut scene = room_scene();
    scene.instances.remove(0);
    scene.environment = Vec3::splat(0.3);
    scene
        .lights
        .push(Light::Point { position: Vec3::new(0.3, 0.8, 0.2), intensity: Vec3::splat(2.0) });
    scene.lights.push(Light::Point {
        position: Vec3::new(-0.4, 0.5, 0.6),
        intensity: Vec3::new(1.0, 0.5, 0.2),
    });
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

/// Both forms at `spp`, the megakernel's dispatches cut to the wavefront's waves (two chunks of
/// 8 samples per pixel), so that both add the same partial sums.
fn both(scene: &SceneDesc, spp: u32) -> (Vec<[f32; 4]>, Vec<[f32; 4]>) {
    let mut sg = SceneGpu::new(gpu(), scene, settings()).expect("scene");
    let mut tracer = PathTracer::new(gpu(), &sg).expect("tracer");
    sg.update(gpu(), scene);
    let pixels = (W * H) as u64;
    let wavefront = Wavefront::with_wave_paths(gpu(), &sg, pixels * 16).expect("wavefront");
    assert_eq!(wavefront.samples_per_wave(&sg), 16);
    tracer.set_paths_per_dispatch(gpu(), pixels * 16).expect("dispatch size");
    assert_eq!(tracer.samples_per_dispatch(), 16);
    let mega = tracer.render_reference(gpu(), &sg, spp, 5, 3, &mut |_, _| {}).expect("megakernel");
    let wave = wavefront.render_reference(gpu(), &sg, &tracer, spp, 5, 3).expect("wavefront");
    (mega, wave)
}

fn assert_same(mega: &[[f32; 4]], wave: &[[f32; 4]]) {
    assert!(mega.iter().any(|p| p[0] > 0.0), "the room is lit");
    // Kernels compiled apart may fuse multiply-adds differently: allow a few ulps per pixel.
    for (i, (a, b)) in mega.iter().zip(wave).enumerate() {
        for c in 0..3 {
            let tolerance = 1e-5 * a[c].abs().max(1e-3);
            assert!(
                (a[c] - b[c]).abs() <= tolerance,
                "pixel {i} channel {c}: megakernel {} wavefront {}",
                a[c],
                b[c]
            );
        }
    }
}

#[test]
fn the_wavefront_renders_the_megakernel_s_image_with_the_panel_alone() {
    // 37 spp: three waves, the last with a partial chunk.
    let (mega, wave) = both(&room_scene(), 37);
    assert_same(&mega, &wave);
}

#[test]
fn the_wavefront_renders_the_megakernel_s_image_with_every_kind_of_light() {
    let scene = lit_room();
    let (mega, wave) = both(&scene, 21);
    assert_same(&mega, &wave);
}

#[test]
fn the_wavefront_follows_passes_compiled_for_every_feature() {
    // The light samples per shading point follow the features the library compiled for.
    let scene = room_scene();
    let mut sg = SceneGpu::new(gpu(), &scene, settings()).expect("scene");
    let mut tracer = PathTracer::new(gpu(), &sg).expect("tracer");
    sg.update(gpu(), &scene);
    sg.library()
        .specialise(gpu(), sg.library_groups(), SceneFeatures::ALL)
        .expect("compile for every feature");
    let pixels = (W * H) as u64;
    let wavefront = Wavefront::with_wave_paths(gpu(), &sg, pixels * 8).expect("wavefront");
    tracer.set_paths_per_dispatch(gpu(), pixels * 8).expect("dispatch size");
    let mega = tracer.render_reference(gpu(), &sg, 8, 1, 0, &mut |_, _| {}).expect("megakernel");
    let wave = wavefront.render_reference(gpu(), &sg, &tracer, 8, 1, 0).expect("wavefront");
    assert_same(&mega, &wave);
}
