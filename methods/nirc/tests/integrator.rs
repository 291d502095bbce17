//! The cache-terminated estimator (shaders/cache_paths.wgsl) is unbiased: with the cache replaced
//! by an oracle (each query answered by an independent Monte Carlo estimate of Lc, the quantity
//! the cache is trained on), the image has the path tracer's mean. The scene has every kind of
//! light (emissive quad, point light, sun with a disk, environment) and a metal sphere.
//!
//! Tolerances come from the renders: block means over several seeds give standard errors, and
//! each block must agree within a number of them. The same check must reject a wrong estimator
//! (the cache term left out), so it has the power to catch a missing or doubled light.

mod common;

use glam::{Mat4, Vec3};
use nirc::config::PredictorMode;
use nirc::{CacheOutput, CachePathSettings, CachePaths, NeuralCache, SceneBounds};
use render::gpu::Gpu;
use render::path_tracer::{PathTracer, PathTracerSettings};
use render::scene::{Camera, Instance, Light, Material, Mesh, SceneDesc};
use render::scene_gpu::SceneGpu;
use std::sync::OnceLock;

const W: u32 = 32;
const H: u32 = 18;
const SEEDS: u64 = 8;
const SPP: u32 = 8;
/// Blocks of 8 x 6 pixels.
const BX: u32 = 8;
const BY: u32 = 6;

fn gpu() -> &'static Gpu {
    static GPU: OnceLock<Gpu> = OnceLock::new();
    GPU.get_or_init(|| Gpu::new().expect("a wgpu adapter (lavapipe on CI)"))
}

fn cube() -> Mesh {
    let p = |x: f32, y: f32, z: f32| Vec3::new(x, y, z) * 0.5;
    let positions = vec![
        p(-1., -1., -1.),
        p(1., -1., -1.),
        p(1., 1., -1.),
        p(-1., 1., -1.),
        p(-1., -1., 1.),
        p(1., -1., 1.),
        p(1., 1., 1.),
        p(-1., 1., 1.),
    ];
    let indices = vec![
        [0, 2, 1],
        [0, 3, 2],
        [4, 5, 6],
        [4, 6, 7],
        [0, 1, 5],
        [0, 5, 4],
        [3, 7, 6],
        [3, 6, 2],
        [0, 4, 7],
        [0, 7, 3],
        [1, 2, 6],
        [1, 6, 5],
    ];
    Mesh { name: "cube".into(), positions, normals: vec![], uvs: vec![], indices }
}

pub fn scene() -> SceneDesc {
    let camera = Camera {
        position: Vec3::new(0.0, 1.2, 3.0),
        target: Vec3::new(0.0, 0.6, 0.0),
        up: Vec3::Y,
        vfov: 55f32.to_radians(),
    };
    SceneDesc {
        meshes: vec![Mesh::plane(2.0), cube(), Mesh::plane(0.5)],
        materials: vec![
            Material { base_color: Vec3::new(0.7, 0.6, 0.5), roughness: 0.8, ..Default::default() },
            Material {
                base_color: Vec3::new(0.9, 0.5, 0.2),
                roughness: 0.4,
                metallic: 1.0,
                ..Default::default()
            },
            Material {
                base_color: Vec3::ZERO,
                emission: Vec3::new(3.0, 2.6, 2.2),
                ..Default::default()
            },
            Material { base_color: Vec3::new(0.2, 0.5, 0.8), ..Default::default() },
        ],
        instances: vec![
            Instance { mesh: 0, material: 0, transform: Mat4::IDENTITY },
            Instance {
                mesh: 1,
                material: 1,
                transform: Mat4::from_scale_rotation_translation(
                    Vec3::splat(0.7),
                    glam::Quat::from_rotation_y(0.5),
                    Vec3::new(-0.4, 0.35, 0.0),
                ),
            },
            Instance {
                mesh: 2,
                material: 2,
                transform: Mat4::from_rotation_translation(
                    glam::Quat::from_rotation_x(std::f32::consts::PI),
                    Vec3::new(0.5, 1.5, 0.3),
                ),
            },
            Instance {
                mesh: 0,
                material: 3,
                transform: Mat4::from_rotation_translation(
                    glam::Quat::from_rotation_x(std::f32::consts::FRAC_PI_2),
                    Vec3::new(0.0, 1.0, -1.0),
                ),
            },
        ],
        lights: vec![
            Light::Point { position: Vec3::new(-1.0, 1.5, 1.0), intensity: Vec3::splat(2.0) },
            Light::Directional {
                direction: Vec3::new(-0.3, -1.0, -0.4),
                irradiance: Vec3::splat(1.0),
                angular_radius: 0.05,
            },
        ],
        environment: Vec3::new(0.1, 0.15, 0.2),
        camera,
        ..Default::default()
    }
}

fn grey(p: &[f32; 4]) -> f64 {
    (p[0] as f64 + p[1] as f64 + p[2] as f64) / 3.0
}

/// Per seed, the mean grey value of each block.
fn block_means(images: &[Vec<[f32; 4]>]) -> Vec<Vec<f64>> {
    images
        .iter()
        .map(|img| {
            let mut sums = vec![0.0; ((W / BX) * (H / BY)) as usize];
            for y in 0..H {
                for x in 0..W {
                    sums[((y / BY) * (W / BX) + x / BX) as usize] +=
                        grey(&img[(y * W + x) as usize]) / (BX * BY) as f64;
                }
            }
            sums
        })
        .collect()
}

/// Largest |z| over blocks of the difference of the two estimators' means.
fn max_z(a: &[Vec<[f32; 4]>], b: &[Vec<[f32; 4]>]) -> f64 {
    let (a, b) = (block_means(a), block_means(b));
    let stats = |m: &[Vec<f64>], k: usize| {
        let n = m.len() as f64;
        let mean = m.iter().map(|v| v[k]).sum::<f64>() / n;
        let var = m.iter().map(|v| (v[k] - mean).powi(2)).sum::<f64>() / (n - 1.0);
        (mean, var / n)
    };
    (0..a[0].len())
        .map(|k| {
            let (ma, va) = stats(&a, k);
            let (mb, vb) = stats(&b, k);
            (ma - mb).abs() / (va + vb + 1e-12).sqrt()
        })
        .fold(0.0, f64::max)
}

enum Answer {
    Oracle,
    Zero,
}

fn cache_images(sg: &SceneGpu, termination_vertex: u32, answer: Answer) -> Vec<Vec<[f32; 4]>> {
    let g = gpu();
    let paths = CachePaths::new(
        g,
        sg,
        SPP,
        CachePathSettings { termination_vertex, train_records: 64, train_steps: 1 },
    )
    .expect("cache paths");
    let out = paths.output(g).unwrap();
    (0..SEEDS)
        .map(|seed| {
            let mut encoder = g.device.create_command_encoder(&Default::default());
            paths.encode_queries(g, &mut encoder, sg, 100 + seed, 0);
            match answer {
                Answer::Oracle => paths.encode_oracle(g, &mut encoder, sg, &out),
                Answer::Zero => encoder.clear_buffer(&out.answers, 0, None),
            }
            paths.encode_resolve(g, &mut encoder, sg, &out);
            g.queue.submit([encoder.finish()]);
            paths.read_image(g, &out).unwrap().0
        })
        .collect()
}

fn scene_gpu(max_depth: u32) -> SceneGpu {
    SceneGpu::new(
        gpu(),
        &scene(),
        PathTracerSettings { width: W, height: H, max_depth, rr_start_depth: 3 },
    )
    .unwrap()
}

fn pt_images(sg: &SceneGpu) -> Vec<Vec<[f32; 4]>> {
    let mut tracer = PathTracer::new(gpu(), sg).unwrap();
    (0..SEEDS).map(|seed| tracer.render(gpu(), sg, SPP, 200 + seed, 0).unwrap().radiance).collect()
}

#[test]
fn oracle_answers_reproduce_the_path_tracer() {
    let t = scene_gpu(5);
    let pt = pt_images(&t);
    for k in [1, 2] {
        let oracle = cache_images(&t, k, Answer::Oracle);
        let z = max_z(&pt, &oracle);
        assert!(
            z < 5.0,
            "termination vertex {k}: oracle image differs from the path tracer by {z:.2} standard errors in some block"
        );
    }
    // The same check rejects the estimator without its cache term.
    let z = max_z(&pt, &cache_images(&t, 1, Answer::Zero));
    assert!(z > 10.0, "leaving the cache term out must be detected, max |z| only {z:.2}");
}

#[test]
fn training_records_are_queries_with_finite_targets() {
    let g = gpu();
    let t = scene_gpu(4);
    let paths = CachePaths::new(
        g,
        &t,
        1,
        CachePathSettings { termination_vertex: 1, train_records: 256, train_steps: 1 },
    )
    .unwrap();
    let mut encoder = g.device.create_command_encoder(&Default::default());
    paths.encode_queries(g, &mut encoder, &t, 7, 3);
    paths.encode_records(g, &mut encoder, &t);
    g.queue.submit([encoder.finish()]);
    let records = paths.read_records(g).unwrap();
    // Camera rays, motion rays and NEE shadow rays; every training record traces at least one.
    let [camera, training] = paths.read_rays(g).unwrap();
    assert!(
        camera > 2 * (W * H) as u64 && training >= 256,
        "rays: camera {camera}, training {training}"
    );
    let queries: Vec<nirc::CacheQuery> =
        render::readback::read_pod(g, paths.queries(), "queries").unwrap();
    let mut distinct = std::collections::HashSet::new();
    for r in &records {
        assert_eq!(r.position[3], 1.0, "every slot holds a valid record: {r:?}");
        let d = r.direction;
        assert!(
            ((d[0] * d[0] + d[1] * d[1] + d[2] * d[2]).sqrt() - 1.0).abs() < 1e-4,
            "unit direction: {r:?}"
        );
        assert!(
            r.target_rgb[..3].iter().all(|v| v.is_finite() && *v >= 0.0),
            "finite non-negative target: {r:?}"
        );
        assert!(
            queries.iter().any(|q| q.position[..3] == r.position[..3] && q.direction[..3] == r.direction[..3]),
            "a record must be one of the frame's queries: {r:?}"
        );
        distinct.insert(r.position.map(f32::to_bits));
    }
    // 256 uniform picks among the V valid queries: V (1 - (1 - 1/V)^256) distinct expected.
    let v = paths.read_query_valid(g).unwrap().iter().filter(|&&b| b).count() as f64;
    let expected = v * (1.0 - (1.0 - 1.0 / v).powi(256));
    assert!(
        distinct.len() as f64 > 0.85 * expected,
        "seeded picks: {} distinct of 256, {expected:.0} expected among {v} valid queries",
        distinct.len()
    );
    // Same frame and seed: the same records, byte for byte.
    let mut encoder = g.device.create_command_encoder(&Default::default());
    paths.encode_queries(g, &mut encoder, &t, 7, 3);
    paths.encode_records(g, &mut encoder, &t);
    g.queue.submit([encoder.finish()]);
    assert_eq!(paths.read_records(g).unwrap(), records);
}

/// One frame of cache-terminated rendering: queries, blended answers, image; then training.
fn cache_frame(
    paths: &CachePaths,
    cache: &NeuralCache,
    sg: &SceneGpu,
    out: &CacheOutput,
    frame: u32,
) -> Vec<[f32; 4]> {
    let g = gpu();
    let mut encoder = g.device.create_command_encoder(&Default::default());
    paths.encode_queries(g, &mut encoder, sg, 5, frame);
    cache
        .encode_infer(
            g,
            &mut encoder,
            paths.queries(),
            paths.query_count(),
            &out.answers,
            PredictorMode::Blend,
        )
        .unwrap();
    paths.encode_resolve(g, &mut encoder, sg, out);
    paths.encode_records(g, &mut encoder, sg);
    cache.encode_train(g, &mut encoder, paths.records(), paths.record_count()).unwrap();
    g.queue.submit([encoder.finish()]);
    paths.read_image(g, out).unwrap().0
}

#[test]
fn saved_and_loaded_cache_renders_the_next_frames_identically() {
    let g = gpu();
    let t = scene_gpu(3);
    let (lo, hi) = t.geometry().bounds();
    let config = common::small_config();
    let paths = CachePaths::new(
        g,
        &t,
        1,
        CachePathSettings { termination_vertex: 1, train_records: 256, train_steps: 1 },
    )
    .unwrap();
    let out = paths.output(g).unwrap();
    let cache =
        NeuralCache::new(g, &config, SceneBounds::new(lo.to_array(), hi.to_array())).unwrap();
    // Past the reliability warm-up (2 updates in small_config), so the blend uses the grid.
    let mut images = Vec::new();
    for frame in 0..4 {
        images.push(cache_frame(&paths, &cache, &t, &out, frame));
    }
    assert_ne!(images[2], images[3], "the cache must be learning");
    // The diagnostic look-up reports the σ the blend used, and the grid is past its warm-up.
    let diag = paths.output(g).unwrap();
    let mut encoder = g.device.create_command_encoder(&Default::default());
    paths.encode_queries(g, &mut encoder, &t, 5, 4);
    cache
        .encode_infer(
            g,
            &mut encoder,
            paths.queries(),
            paths.query_count(),
            &out.answers,
            PredictorMode::Blend,
        )
        .unwrap();
    cache
        .encode_reliability(g, &mut encoder, paths.queries(), paths.query_count(), &diag.answers)
        .unwrap();
    g.queue.submit([encoder.finish()]);
    let (blend, rel) =
        (paths.read_answers(g, &out).unwrap(), paths.read_answers(g, &diag).unwrap());
    assert!(rel.iter().all(|r| r[3] == 1.0), "grid warmed up");
    assert!(
        blend.iter().zip(&rel).all(|(b, r)| b[3] == r[2]),
        "σ of the blend = σ of the diagnostics"
    );
    assert!(rel.iter().any(|r| r[0] != r[1]), "the two predictors' reliabilities differ somewhere");
    let tmp = tempfile::tempdir().unwrap();
    let file = tmp.path().join("nirc-integrator.state");
    cache.save(g, &file).unwrap();
    let loaded = NeuralCache::load(g, &file).unwrap();
    for frame in 4..6 {
        let a = cache_frame(&paths, &cache, &t, &out, frame);
        let b = cache_frame(&paths, &loaded, &t, &out, frame);
        assert_eq!(
            bytemuck::cast_slice::<[f32; 4], u8>(&a),
            bytemuck::cast_slice::<[f32; 4], u8>(&b),
            "frame {frame} after save/load"
        );
    }
}

#[test]
fn motion_vectors_match_the_path_tracers_gbuffer() {
    // Camera moved and an instance moved between two updates: the cache paths' per-pixel motion
    // is the path tracer's G-buffer motion of the same frame.
    let g = gpu();
    let mut t = scene_gpu(2);
    let mut moved = scene();
    moved.camera.position += Vec3::new(0.15, -0.05, 0.1);
    moved.instances[1].transform =
        Mat4::from_translation(Vec3::new(0.1, 0.0, 0.05)) * moved.instances[1].transform;
    t.update(g, &moved);
    let expected = PathTracer::new(g, &t).unwrap().render(g, &t, 1, 3, 1).unwrap().gbuffer.motion;
    let paths = CachePaths::new(g, &t, 1, CachePathSettings::default()).unwrap();
    let mut encoder = g.device.create_command_encoder(&Default::default());
    paths.encode_queries(g, &mut encoder, &t, 3, 1);
    g.queue.submit([encoder.finish()]);
    let got = paths.read_motion(g).unwrap();
    assert_eq!(got.len(), expected.len());
    let moving = expected.iter().filter(|m| m[0].abs() + m[1].abs() > 0.5).count();
    assert!(
        moving > expected.len() / 2,
        "the test needs motion: {moving} of {} pixels move",
        expected.len()
    );
    for (i, (a, b)) in got.iter().zip(&expected).enumerate() {
        assert!(
            (a[0] - b[0]).abs() < 1e-3 && (a[1] - b[1]).abs() < 1e-3,
            "pixel {i}: {a:?} vs G-buffer {b:?}"
        );
    }
}

#[test]
fn ray_counters_count_every_ray_when_all_escape() {
    // Looking straight up, every camera ray escapes: per pixel `spp` camera rays and one motion
    // ray, no termination vertex, hence no query and no training ray.
    let g = gpu();
    let mut up = scene();
    up.camera.target = up.camera.position + Vec3::new(0.0, 10.0, 0.01);
    let mut t = scene_gpu(3);
    t.update(g, &up);
    let spp = 2;
    let paths = CachePaths::new(
        g,
        &t,
        spp,
        CachePathSettings { termination_vertex: 1, train_records: 64, train_steps: 1 },
    )
    .unwrap();
    let mut encoder = g.device.create_command_encoder(&Default::default());
    paths.encode_queries(g, &mut encoder, &t, 5, 2);
    paths.encode_records(g, &mut encoder, &t);
    g.queue.submit([encoder.finish()]);
    assert!(
        paths.read_query_valid(g).unwrap().iter().all(|v| !v),
        "the test needs every camera ray to escape"
    );
    assert_eq!(paths.read_rays(g).unwrap(), [(W * H * (spp + 1)) as u64, 0]);
}
