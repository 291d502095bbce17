//! TAA on the GPU: the resolve against its CPU reference, reprojection under a known camera
//! translation, rejection on disocclusion, convergence and stability on a static scene.

use glam::{Mat4, Vec2, Vec3};
use render::gpu::Gpu;
use render::path_tracer::{NO_HIT, PathTracer, PathTracerSettings};
use render::scene::{Camera, Instance, Material, Mesh, SceneDesc};
use render::scene_gpu::SceneGpu;
use std::sync::OnceLock;
use taa::{Taa, TaaClamp, TaaSettings, resolve_cpu};

const W: u32 = 32;
const H: u32 = 18;
const HEIGHT: f32 = 4.0;
const VFOV: f32 = 0.8;

fn gpu() -> &'static Gpu {
    static GPU: OnceLock<Gpu> = OnceLock::new();
    GPU.get_or_init(|| Gpu::new().expect("a wgpu adapter (lavapipe on CI)"))
}

/// Square in the y = 0 plane, side 2 * half, front face +y.
fn square(half: f32) -> Mesh {
    Mesh {
        name: "square".into(),
        positions: vec![
            Vec3::new(-half, 0.0, -half),
            Vec3::new(-half, 0.0, half),
            Vec3::new(half, 0.0, half),
            Vec3::new(half, 0.0, -half),
        ],
        normals: vec![],
        uvs: vec![],
        indices: vec![[0, 1, 2], [0, 2, 3]],
    }
}

fn camera_at(x: f32) -> Camera {
    Camera {
        position: Vec3::new(x, HEIGHT, 0.0),
        target: Vec3::new(x, 0.0, 0.0),
        up: Vec3::NEG_Z,
        vfov: VFOV,
    }
}

/// World size of one pixel on the ground seen by the top-down camera.
fn pixel_size() -> f32 {
    2.0 * HEIGHT * (0.5 * VFOV).tan() / H as f32
}

/// A black ground and an emissive square lying on it, at `square_x`: noise-free images (the
/// camera sees emission or black), so reprojection errors show exactly.
fn feature_scene(square_x: f32) -> SceneDesc {
    let black = Material { base_color: Vec3::ZERO, specular: 0.0, ..Default::default() };
    let emitter = Material {
        base_color: Vec3::ZERO,
        emission: Vec3::new(2.0, 1.0, 0.5),
        specular: 0.0,
        ..Default::default()
    };
    SceneDesc {
        meshes: vec![square(20.0), square(4.0 * pixel_size())],
        materials: vec![black, emitter],
        instances: vec![
            Instance { mesh: 0, material: 0, transform: Mat4::IDENTITY },
            Instance {
                mesh: 1,
                material: 1,
                transform: Mat4::from_translation(Vec3::new(square_x, 0.01, 0.0)),
            },
        ],
        camera: camera_at(0.0),
        ..Default::default()
    }
}

fn scene_gpu(scene: &SceneDesc, max_depth: u32) -> SceneGpu {
    SceneGpu::new(
        gpu(),
        scene,
        PathTracerSettings { width: W, height: H, max_depth, rr_start_depth: 3 },
    )
    .expect("scene")
}

fn assert_matches_cpu(taa: &Taa, what: &str) {
    let i = taa.inspect(gpu()).expect("inspect");
    let expected = resolve_cpu::resolve(
        &taa.settings(),
        (W, H),
        i.params_history_valid,
        &i.current,
        &i.primary,
        &i.previous_primary,
        &i.history,
    );
    for (k, (g, c)) in i.resolved.iter().zip(&expected).enumerate() {
        for ch in 0..4 {
            assert!(
                (g[ch] - c[ch]).abs() <= 1e-4 * (1.0 + c[ch].abs()),
                "{what}: pixel {k} channel {ch}: GPU {g:?} CPU {c:?}"
            );
        }
    }
}

#[test]
fn reprojection_follows_a_camera_translation_and_matches_the_cpu_resolve() {
    let shift = 8.0;
    for clamp in [TaaClamp::None, TaaClamp::MinMax, TaaClamp::Variance { gamma: 1.0 }] {
        let mut scene = feature_scene(0.0);
        let mut sg = scene_gpu(&scene, 1);
        let settings = TaaSettings { clamp, ..Default::default() };
        let mut taa = Taa::new(gpu(), &sg, settings).expect("taa");
        let f0 = taa.render(gpu(), &sg, 1, 0).expect("frame 0");
        assert!(f0.history_length.iter().all(|&l| l == 1.0));
        assert_matches_cpu(&taa, "frame 0");
        // The camera moves right by `shift` pixels' worth: the ground moves left in the image.
        scene.camera = camera_at(shift * pixel_size());
        sg.update(gpu(), &scene);
        let f1 = taa.render(gpu(), &sg, 1, 1).expect("frame 1");
        assert_matches_cpu(&taa, &format!("frame 1, {clamp:?}"));
        let i = taa.inspect(gpu()).unwrap();
        for (k, p) in i.primary.iter().enumerate() {
            assert_ne!(p.instance, NO_HIT);
            // 0.03 px: the square lies 1 cm above the ground (0.25 % nearer).
            assert!(
                (Vec2::from(p.motion) - Vec2::new(shift, 0.0)).length() < 3e-2,
                "pixel {k}: motion {:?}",
                p.motion
            );
        }
        // Square (8 px wide) centred on the image before, 8 px to the left now. Away from the
        // jittered edges the resolved image equals the current one: no ghost where the square
        // was, the full emission where it is.
        let emission = 2.0;
        let (cx, cy) = (W as i32 / 2, H as i32 / 2);
        for y in cy - 2..cy + 2 {
            for x in 0..W as i32 {
                let now = (x - (cx - shift as i32)).abs();
                let before = (x - cx).abs();
                let idx = (y as u32 * W + x as u32) as usize;
                let r = f1.radiance[idx][0];
                if now <= 2 {
                    assert!(
                        (r - emission).abs() < 1e-4,
                        "{clamp:?}: inside the square at ({x}, {y}): {r}"
                    );
                    assert_eq!(f1.history_length[idx], 2.0, "({x}, {y})");
                } else if now >= 6 && before >= 6 {
                    assert!(r.abs() < 1e-4, "{clamp:?}: ground at ({x}, {y}): {r}");
                } else if now >= 6 && before <= 2 {
                    assert!(
                        r.abs() < 1e-4,
                        "{clamp:?}: ghost where the square was, ({x}, {y}): {r}"
                    );
                }
            }
        }
    }
}

#[test]
fn history_is_rejected_where_the_ground_is_disoccluded() {
    let mut scene = feature_scene(0.0);
    let mut sg = scene_gpu(&scene, 1);
    let mut taa = Taa::new(gpu(), &sg, TaaSettings { clamp: TaaClamp::None, ..Default::default() })
        .expect("taa");
    taa.render(gpu(), &sg, 1, 0).unwrap();
    // The square moves 4 px right; the camera stays.
    scene.instances[1].transform = Mat4::from_translation(Vec3::new(4.0 * pixel_size(), 0.01, 0.0));
    sg.update(gpu(), &scene);
    let f1 = taa.render(gpu(), &sg, 1, 1).unwrap();
    assert_matches_cpu(&taa, "moving square");
    let (cx, cy) = (W as i32 / 2, H as i32 / 2);
    let mut disoccluded = 0;
    for y in cy - 2..cy + 2 {
        for x in 0..W as i32 {
            let idx = (y as u32 * W + x as u32) as usize;
            let was_square = (x - cx).abs() <= 2; // [cx-4, cx+4) before, 1 px margin
            let is_square = (x - (cx + 4)).abs() <= 2;
            let was_far = (x - cx).abs() >= 6;
            let is_far = (x - (cx + 4)).abs() >= 6;
            if was_square && is_far {
                assert_eq!(
                    f1.history_length[idx], 1.0,
                    "disoccluded ground at ({x}, {y}) kept its history"
                );
                assert!(f1.radiance[idx][0].abs() < 1e-4);
                disoccluded += 1;
            } else if (is_square) || (was_far && is_far) {
                assert_eq!(f1.history_length[idx], 2.0, "({x}, {y}) lost its history");
            }
        }
    }
    assert!(disoccluded > 0);
}

/// Ground and a box under sky light and a sun: a noisy 1 spp image.
fn lit_scene() -> SceneDesc {
    let grey = Material { base_color: Vec3::splat(0.6), specular: 0.0, ..Default::default() };
    let cube = Mesh {
        name: "cube".into(),
        positions: vec![
            Vec3::new(-1.0, 0.0, -1.0),
            Vec3::new(1.0, 0.0, -1.0),
            Vec3::new(1.0, 0.0, 1.0),
            Vec3::new(-1.0, 0.0, 1.0),
            Vec3::new(-1.0, 2.0, -1.0),
            Vec3::new(1.0, 2.0, -1.0),
            Vec3::new(1.0, 2.0, 1.0),
            Vec3::new(-1.0, 2.0, 1.0),
        ],
        normals: vec![],
        uvs: vec![],
        indices: vec![
            [4, 6, 5],
            [4, 7, 6],
            [0, 1, 5],
            [0, 5, 4],
            [1, 2, 6],
            [1, 6, 5],
            [2, 3, 7],
            [2, 7, 6],
            [3, 0, 4],
            [3, 4, 7],
        ],
    };
    SceneDesc {
        meshes: vec![square(20.0), cube],
        materials: vec![grey],
        instances: vec![
            Instance { mesh: 0, material: 0, transform: Mat4::IDENTITY },
            Instance { mesh: 1, material: 0, transform: Mat4::from_scale(Vec3::splat(0.6)) },
        ],
        lights: vec![render::scene::Light::Directional {
            direction: Vec3::new(-0.4, -1.0, -0.3).normalize(),
            irradiance: Vec3::splat(2.0),
            angular_radius: 0.05,
        }],
        environment: Vec3::new(0.3, 0.4, 0.5),
        camera: Camera {
            position: Vec3::new(0.0, 3.0, 4.0),
            target: Vec3::ZERO,
            up: Vec3::Y,
            vfov: 0.9,
        },
        ..Default::default()
    }
}

fn mse(a: &[[f32; 4]], b: &[[f32; 4]]) -> f64 {
    a.iter()
        .zip(b)
        .map(|(x, y)| (0..3).map(|c| ((x[c] - y[c]) as f64).powi(2)).sum::<f64>() / 3.0)
        .sum::<f64>()
        / a.len() as f64
}

fn smape(a: &[[f32; 4]], b: &[[f32; 4]]) -> f64 {
    a.iter()
        .zip(b)
        .map(|(x, y)| {
            (0..3)
                .map(|c| ((x[c] - y[c]).abs() / (x[c].abs() + y[c].abs() + 0.01)) as f64)
                .sum::<f64>()
                / 3.0
        })
        .sum::<f64>()
        / a.len() as f64
}

#[test]
fn static_scene_converges_and_flickers_less_than_1spp() {
    let scene = lit_scene();
    let sg = scene_gpu(&scene, 4);
    let mut pt = PathTracer::new(gpu(), &sg).expect("path tracer");
    let reference = pt.render_reference(gpu(), &sg, 1024, 99, 0, &mut |_, _| {}).unwrap();
    let mut taa = Taa::new(gpu(), &sg, TaaSettings::default()).expect("taa");
    let frames = 16;
    let (mut taa_frames, mut pt_frames) = (vec![], vec![]);
    for f in 0..frames {
        taa_frames.push(taa.render(gpu(), &sg, 5, f).unwrap().radiance);
        pt_frames.push(pt.render(gpu(), &sg, 1, 5, f).unwrap().radiance);
    }
    assert_matches_cpu(&taa, "static scene, last frame");
    let errors: Vec<f64> = taa_frames.iter().map(|img| mse(img, &reference)).collect();
    let pt_error = pt_frames.iter().map(|img| mse(img, &reference)).sum::<f64>() / frames as f64;
    // Falls with frames: the last quarter is well below the first frame and below 1 spp.
    let late = errors[12..].iter().sum::<f64>() / 4.0;
    assert!(late < 0.5 * errors[0], "MSE by frame {errors:?}");
    assert!(late < 0.5 * pt_error, "TAA MSE {late} vs 1 spp {pt_error}");
    let flicker = |v: &[Vec<[f32; 4]>]| {
        (8..frames as usize).map(|f| smape(&v[f], &v[f - 1])).sum::<f64>() / (frames as f64 - 8.0)
    };
    let (taa_flicker, pt_flicker) = (flicker(&taa_frames), flicker(&pt_frames));
    assert!(
        taa_flicker < 0.5 * pt_flicker,
        "frame-to-frame SMAPE: TAA {taa_flicker} vs 1 spp {pt_flicker}"
    );
}

#[test]
fn same_inputs_give_identical_bytes() {
    let scene = lit_scene();
    let run = || {
        let sg = scene_gpu(&scene, 3);
        let mut taa = Taa::new(gpu(), &sg, TaaSettings::default()).expect("taa");
        (0..3).map(|f| taa.render(gpu(), &sg, 7, f).unwrap().radiance).collect::<Vec<_>>()
    };
    assert_eq!(run(), run());
}

/// Every primary ray escapes (the camera looks up, away from the ground): each path is exactly
/// its camera ray, so the GPU ray counters have exact expected values.
#[test]
fn ray_counters_are_exact_when_every_ray_escapes() {
    let mut scene = feature_scene(0.0);
    scene.camera = Camera {
        position: Vec3::new(0.0, HEIGHT, 0.0),
        target: Vec3::new(0.0, 2.0 * HEIGHT, 0.0),
        up: Vec3::NEG_Z,
        vfov: VFOV,
    };
    let mut sg = scene_gpu(&scene, 4);
    let mut pt = PathTracer::new(gpu(), &sg).expect("path tracer");
    sg.update(gpu(), &scene);
    let pixels = (W * H) as u64;
    let out = pt.render(gpu(), &sg, 3, 5, 0).expect("pt frame");
    assert!(out.gbuffer.instance_id.iter().all(|&i| i == NO_HIT), "the view must see only sky");
    // G-buffer ray + 3 camera rays per pixel.
    assert_eq!((out.rays, out.shaded), (4 * pixels, 3 * pixels));
    assert_eq!(
        out.timings.iter().map(|t| t.pass.as_str()).collect::<Vec<_>>(),
        ["gbuffer", "path_trace"]
    );
    let mut taa = Taa::new(gpu(), &sg, TaaSettings::default()).expect("taa");
    for f in 0..2 {
        let t = taa.render(gpu(), &sg, 5, f).expect("taa frame");
        // The primary-attribute ray + the path's camera ray, per pixel, every frame (cleared).
        assert_eq!((t.rays, t.shaded), (2 * pixels, pixels), "frame {f}");
        assert_eq!(
            t.timings.iter().map(|t| t.pass.as_str()).collect::<Vec<_>>(),
            ["taa_trace", "taa_resolve"]
        );
    }
    let mut cache = hash_cache::HashCache::new(gpu(), &sg, Default::default()).expect("hash cache");
    let h = cache.render(gpu(), &sg, &scene.camera, 5, 0, None).expect("hash cache frame");
    // One camera ray per pixel, no cache update path (nothing was hit).
    assert_eq!((h.rays, h.shaded, h.stats.update_paths), (pixels, pixels, 0));
}

#[test]
fn wall_clock_times_each_pass_on_its_own() {
    use render::timing::{Clock, PassTimer};
    let timer = PassTimer::wall(&["first", "second"]);
    assert_eq!(timer.clock(), Clock::Wall);
    let buffer = gpu().device.create_buffer(&wgpu::BufferDescriptor {
        label: None,
        size: 256,
        usage: wgpu::BufferUsages::STORAGE | wgpu::BufferUsages::COPY_DST,
        mapped_at_creation: false,
    });
    let outside = std::time::Instant::now();
    let mut frame = timer.begin(gpu(), "test");
    frame.encoder().clear_buffer(&buffer, 0, None);
    frame.pass(1, |_| {}).expect("pass");
    let timings = frame.submit().expect("submit");
    let outside_ms = outside.elapsed().as_secs_f64() * 1e3;
    // Only the pass recorded is reported, under its own name and the wall clock.
    assert_eq!(timings.len(), 1);
    assert_eq!((timings[0].pass.as_str(), timings[0].clock), ("second", Clock::Wall));
    // A pass's wall time lies within the wall time around the whole frame (in ms, not s or us).
    let ms = timings[0].ms;
    assert!(ms > 0.0 && ms <= outside_ms, "pass {ms} ms, whole frame {outside_ms} ms");
    let gpu_timer = PassTimer::new(gpu(), &["only"]);
    assert_eq!(gpu_timer.clock() == Clock::Gpu, gpu().has_timestamps());
}

#[test]
fn equal_passes_share_their_pipelines() {
    // Two TAA instances on one scene compile the trace pass once; another pass does not alias.
    let sg = scene_gpu(&feature_scene(0.0), 2);
    use render::compute::BufferBinding;
    let own = [
        BufferBinding::read("taa", "TaaParams"),
        BufferBinding::read_write("taa_current", "array<vec4f>"),
        BufferBinding::read_write("taa_primary", "array<TaaPrimary>"),
        BufferBinding::read_write("taa_counters", "array<atomic<u32>>"),
    ];
    let (layout_a, [a]) = sg
        .library_pass(gpu(), "taa_trace.wgsl", Taa::trace_program(), &own, ["taa_trace"])
        .unwrap();
    let (layout_b, [b]) = sg
        .library_pass(gpu(), "taa_trace.wgsl", Taa::trace_program(), &own, ["taa_trace"])
        .unwrap();
    assert!(a == b && layout_a == layout_b, "the same pass was compiled twice");
    let (_, [c]) = sg
        .library_pass(gpu(), "taa_trace.wgsl (copy)", Taa::trace_program(), &own, ["taa_trace"])
        .unwrap();
    assert!(a != c, "a pass of another name must get its own pipeline");
    // Both TAA instances still render (they bind their own buffers to the shared pipeline).
    let (mut one, mut two) = (
        Taa::new(gpu(), &sg, TaaSettings::default()).unwrap(),
        Taa::new(gpu(), &sg, TaaSettings::default()).unwrap(),
    );
    let (x, y) = (one.render(gpu(), &sg, 1, 0).unwrap(), two.render(gpu(), &sg, 1, 0).unwrap());
    assert_eq!(x.radiance, y.radiance, "the same frame through a shared pipeline");
}
