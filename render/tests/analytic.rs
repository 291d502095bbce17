//! The path tracer against closed forms: furnace, point / directional / spot lights and an
//! emissive rectangle over a diffuse plane, determinism, reference stability, and the G-buffer.
//!
//! Tolerances come from the images themselves: two renders with different seeds give an
//! unbiased estimate of the per-pixel Monte Carlo variance (E[(a - b)^2] / 2), and every check is
//! a number of those standard deviations (plus a float allowance), never a guessed percentage.
//! Expected values are averaged over each pixel's footprint (the jittered primary rays sample
//! it uniformly) with the same camera model on the CPU.

use glam::{Mat4, Vec2, Vec3};
use render::frame::CameraBasis;
use render::gpu::Gpu;
use render::path_tracer::{FrameOutput, NO_HIT, PathTracer, PathTracerSettings};
use render::scene::{Camera, Instance, Light, Material, Mesh, SceneDesc, Texture};
use render::scene_gpu::SceneGpu;
use std::f64::consts::PI;
use std::sync::OnceLock;

const W: u32 = 48;
const H: u32 = 32;

fn gpu() -> &'static Gpu {
    static GPU: OnceLock<Gpu> = OnceLock::new();
    GPU.get_or_init(|| Gpu::new().expect("a wgpu adapter (lavapipe on CI)"))
}

/// Flat-shaded UV sphere of radius 1 (a convex polyhedron).
fn sphere(segments: u32, rings: u32) -> Mesh {
    let mut positions = vec![];
    for r in 0..=rings {
        let theta = PI as f32 * r as f32 / rings as f32;
        for s in 0..segments {
            let phi = 2.0 * PI as f32 * s as f32 / segments as f32;
            positions.push(Vec3::new(
                theta.sin() * phi.cos(),
                theta.cos(),
                theta.sin() * phi.sin(),
            ));
        }
    }
    let mut indices = vec![];
    for r in 0..rings {
        for s in 0..segments {
            let a = r * segments + s;
            let b = r * segments + (s + 1) % segments;
            let c = a + segments;
            let d = b + segments;
            if r != 0 {
                indices.push([a, b, c]);
            }
            if r != rings - 1 {
                indices.push([b, d, c]);
            }
        }
    }
    Mesh { name: "sphere".into(), positions, normals: vec![], uvs: vec![], indices }
}

fn lambert(albedo: f32) -> Material {
    Material { base_color: Vec3::splat(albedo), specular: 0.0, ..Default::default() }
}

fn top_down_camera(height: f32) -> Camera {
    Camera {
        position: Vec3::new(0.0, height, 0.0),
        target: Vec3::ZERO,
        up: Vec3::NEG_Z,
        vfov: 50f32.to_radians(),
    }
}

fn settings(max_depth: u32) -> PathTracerSettings {
    PathTracerSettings { width: W, height: H, max_depth, rr_start_depth: 3 }
}

fn render(scene: &SceneDesc, s: PathTracerSettings, spp: u32, seed: u64) -> FrameOutput {
    let sg = SceneGpu::new(gpu(), scene, s).expect("scene");
    let mut pt = PathTracer::new(gpu(), &sg).expect("path tracer");
    pt.render(gpu(), &sg, spp, seed, 0).expect("render")
}

/// With ANALYTIC_DUMP=dir set, writes `values` (W x H f64, row-major) as raw little-endian f64
/// for inspection.
fn dump(name: &str, values: impl IntoIterator<Item = f64>) {
    if let Ok(dir) = std::env::var("ANALYTIC_DUMP") {
        let bytes: Vec<u8> = values.into_iter().flat_map(|v| v.to_le_bytes()).collect();
        std::fs::write(format!("{dir}/{name}.f64"), bytes).unwrap();
    }
}

fn mean_rgb(p: &[f32; 4]) -> f64 {
    (p[0] as f64 + p[1] as f64 + p[2] as f64) / 3.0
}

/// Independent renders of the same scene (seeds `seed..seed + RENDERS`), per-pixel grey values.
const RENDERS: u64 = 8;

fn renders(scene: &SceneDesc, s: PathTracerSettings, spp: u32, seed: u64) -> Vec<Vec<f64>> {
    let sg = SceneGpu::new(gpu(), scene, s).expect("scene");
    let mut pt = PathTracer::new(gpu(), &sg).expect("path tracer");
    (seed..seed + RENDERS)
        .map(|k| {
            pt.render(gpu(), &sg, spp, k, 0)
                .expect("render")
                .radiance
                .iter()
                .map(mean_rgb)
                .collect()
        })
        .collect()
}

/// Compares the mean of independent renders with `expected` per pixel. Each pixel's standard
/// error comes from the spread of its own renders (Student t with RENDERS - 1 = 7 degrees of
/// freedom: |t| > 10 has probability 2e-5), and the mean error over all pixels must be within
/// 5 of its pooled standard errors; `slack` (relative) absorbs float rounding where the
/// estimate is noise-free (delta lights). Returns the mean relative standard error.
fn assert_matches(what: &str, renders: &[Vec<f64>], expected: &[f64], slack: f64) -> f64 {
    let n = expected.len();
    let r = renders.len() as f64;
    let (mut sum_err, mut sum_var, mut sum_rel) = (0.0, 0.0, 0.0);
    for i in 0..n {
        let e = expected[i];
        let mean = renders.iter().map(|x| x[i]).sum::<f64>() / r;
        let var = renders.iter().map(|x| (x[i] - mean).powi(2)).sum::<f64>() / (r - 1.0);
        let standard_error = (var / r).sqrt();
        sum_err += mean - e;
        sum_var += var / r;
        sum_rel += standard_error / e.abs().max(1e-12);
        let (x, y) = (i as u32 % W, i as u32 / W);
        assert!(
            (mean - e).abs() <= 10.0 * standard_error + slack * e.abs(),
            "{what}: pixel ({x}, {y}) = {mean:.5} expected {e:.5} (standard error {standard_error:.2e}, renders {:?})",
            renders.iter().map(|v| v[i] as f32).collect::<Vec<_>>()
        );
    }
    assert!(
        sum_err.abs()
            <= 5.0 * sum_var.sqrt() + slack * expected.iter().map(|e| e.abs()).sum::<f64>(),
        "{what}: summed error {sum_err:.4e} over {n} pixels, standard error {:.4e}",
        sum_var.sqrt()
    );
    sum_rel / n as f64
}

fn pick(renders: &[Vec<f64>], pixels: &[usize]) -> Vec<Vec<f64>> {
    renders.iter().map(|img| pixels.iter().map(|&i| img[i]).collect()).collect()
}

/// Average of `f` over each pixel's footprint (16 x 16 stratified points), as the jittered
/// primary rays see it; `f` gets the ray origin and unit direction.
fn footprint_average(camera: &Camera, f: impl Fn(Vec3, Vec3) -> f64) -> Vec<f64> {
    let basis = CameraBasis::new(camera, W, H);
    let k = 16;
    let mut out = Vec::with_capacity((W * H) as usize);
    for y in 0..H {
        for x in 0..W {
            let mut sum = 0.0;
            for j in 0..k {
                for i in 0..k {
                    let p = Vec2::new(
                        x as f32 + (i as f32 + 0.5) / k as f32,
                        y as f32 + (j as f32 + 0.5) / k as f32,
                    );
                    sum += f(camera.position, basis.ray_direction(p, W, H));
                }
            }
            out.push(sum / (k * k) as f64);
        }
    }
    out
}

/// Point where a ray meets the y = 0 plane.
fn hit_ground(o: Vec3, d: Vec3) -> Vec3 {
    let t = -o.y / d.y;
    o + t * d
}

fn ground_scene(albedo: f32, camera: Camera) -> SceneDesc {
    SceneDesc {
        meshes: vec![Mesh::plane(50.0)],
        materials: vec![lambert(albedo)],
        instances: vec![Instance { mesh: 0, material: 0, transform: Mat4::IDENTITY }],
        camera,
        ..Default::default()
    }
}

/// A white Lambertian sphere resting on a white plane in a constant environment L = 1.
fn white_furnace() -> SceneDesc {
    let camera = Camera {
        position: Vec3::new(0.0, 1.5, 4.0),
        target: Vec3::new(0.0, 0.7, 0.0),
        up: Vec3::Y,
        vfov: 60f32.to_radians(),
    };
    SceneDesc {
        meshes: vec![Mesh::plane(3.0), sphere(24, 12)],
        materials: vec![lambert(1.0)],
        instances: vec![
            Instance { mesh: 0, material: 0, transform: Mat4::IDENTITY },
            Instance {
                mesh: 1,
                material: 0,
                transform: Mat4::from_translation(Vec3::new(0.0, 1.0, 0.0)),
            },
        ],
        environment: Vec3::ONE,
        camera,
        ..Default::default()
    }
}

#[test]
fn furnace_albedo_one_scene_renders_the_environment() {
    // Every surface white Lambertian inside a constant environment L = 1: whatever the geometry
    // (here a sphere resting on a plane: concave corners, many bounces), radiance is 1 everywhere.
    let scene = white_furnace();
    let s = PathTracerSettings { max_depth: 64, rr_start_depth: 64, ..settings(64) };
    let first = render(&scene, s, 1, 0);
    let hits = first.gbuffer.instance_id.iter().filter(|&&i| i != NO_HIT).count();
    assert!(hits > (W * H / 2) as usize, "the camera should mostly see the objects ({hits} hits)");
    let images = renders(&scene, s, 8, 1);
    dump("furnace", images[0].iter().cloned());
    let relative_error = assert_matches("furnace", &images, &vec![1.0; (W * H) as usize], 1e-4);
    assert!(relative_error < 0.05, "furnace noise {relative_error}");
}

#[test]
fn long_dispatch_keeps_every_sample() {
    // Thousands of deep paths per pixel in ONE dispatch. llvmpipe (Mesa 22) silently ends all of
    // an invocation's loops after 65535 iterations in total; a thread that looped over its
    // samples returned a sum of only the first few hundred while the count said thousands, and
    // the image came out several times too dark. The furnace must stay at 1.
    let scene = white_furnace();
    let s = PathTracerSettings { width: 8, height: 6, max_depth: 64, rr_start_depth: 64 };
    let sg = SceneGpu::new(gpu(), &scene, s).unwrap();
    let mut pt = PathTracer::new(gpu(), &sg).unwrap();
    let spp = 2048;
    assert!(pt.samples_per_dispatch() >= spp, "the test needs all samples in one dispatch");
    let mut dispatches = 0;
    let image = pt.render_reference(gpu(), &sg, spp, 5, 0, &mut |_, _| dispatches += 1).unwrap();
    assert_eq!(dispatches, 1);
    let mean = image.iter().map(mean_rgb).sum::<f64>() / image.len() as f64;
    let worst = image.iter().map(|p| (mean_rgb(p) - 1.0).abs()).fold(0.0, f64::max);
    assert!(
        (mean - 1.0).abs() < 0.01 && worst < 0.05,
        "furnace at {spp} spp in one dispatch: mean {mean}, worst pixel off by {worst}"
    );
}

#[test]
fn furnace_convex_object_reflects_its_albedo() {
    // A convex Lambertian object of albedo a in a constant environment L: every point sees only
    // the environment over its hemisphere, so the reflected radiance is exactly a L.
    let camera = Camera {
        position: Vec3::new(0.0, 0.0, 1.6),
        target: Vec3::ZERO,
        up: Vec3::Y,
        vfov: 30f32.to_radians(),
    };
    let scene = SceneDesc {
        meshes: vec![sphere(32, 16)],
        materials: vec![lambert(0.5)],
        instances: vec![Instance { mesh: 0, material: 0, transform: Mat4::IDENTITY }],
        environment: Vec3::splat(2.0),
        camera,
        ..Default::default()
    };
    let s = settings(8);
    assert!(
        render(&scene, s, 1, 0).gbuffer.instance_id.iter().all(|&i| i == 0),
        "the sphere must fill the image"
    );
    assert_matches("convex furnace", &renders(&scene, s, 4, 3), &vec![1.0; (W * H) as usize], 1e-4);
}

#[test]
fn point_light_over_diffuse_plane() {
    let albedo = 0.7;
    let light = Vec3::new(0.3, 1.0, 0.2);
    let intensity = 5.0;
    let camera = top_down_camera(2.5);
    let mut scene = ground_scene(albedo, camera);
    scene.lights = vec![Light::Point { position: light, intensity: Vec3::splat(intensity) }];
    let s = settings(1);
    let images = renders(&scene, s, 4, 5);
    // L = albedo / pi * I cos(theta) / r^2
    let expected = footprint_average(&camera, |o, d| {
        let p = hit_ground(o, d);
        let to_light = light - p;
        let r2 = to_light.length_squared() as f64;
        albedo as f64 / PI * intensity as f64 * (to_light.y as f64 / r2.sqrt()) / r2
    });
    assert_matches("point light", &images, &expected, 2e-4);
}

#[test]
fn directional_lights_give_e_cos_theta() {
    // For a disk of directions wholly above the horizon, the irradiance is E cos(theta_axis)
    // exactly; the delta light (radius 0) and the cone (radius 0.1 rad) must agree with it.
    let albedo = 0.6;
    let e = 2.0;
    let theta = 30f32.to_radians();
    let direction = Vec3::new(theta.sin(), -theta.cos(), 0.0);
    let expected = albedo as f64 / PI * e as f64 * theta.cos() as f64;
    for angular_radius in [0.0, 0.1] {
        let mut scene = ground_scene(albedo, top_down_camera(2.0));
        scene.lights =
            vec![Light::Directional { direction, irradiance: Vec3::splat(e), angular_radius }];
        let s = settings(1);
        let images = renders(&scene, s, 4, 7);
        assert_matches(
            &format!("directional light, radius {angular_radius}"),
            &images,
            &vec![expected; (W * H) as usize],
            2e-4,
        );
    }
}

fn spot_falloff(cos_axis: f64, cos_outer: f64, cos_inner: f64) -> f64 {
    let t = ((cos_axis - cos_outer) / (cos_inner - cos_outer)).clamp(0.0, 1.0);
    t * t * (3.0 - 2.0 * t)
}

#[test]
fn spot_light_over_diffuse_plane() {
    let albedo = 0.8;
    let position = Vec3::new(-0.2, 1.2, 0.1);
    let axis = Vec3::new(0.3, -1.0, 0.1).normalize();
    let (inner, outer) = (25f32.to_radians(), 60f32.to_radians());
    let intensity = 4.0;
    let camera = top_down_camera(2.0);
    let mut scene = ground_scene(albedo, camera);
    scene.lights = vec![Light::Spot {
        position,
        direction: axis,
        intensity: Vec3::splat(intensity),
        inner_angle: inner,
        outer_angle: outer,
    }];
    let s = settings(1);
    let images = renders(&scene, s, 4, 9);
    let expected_full = footprint_average(&camera, |o, d| {
        let p = hit_ground(o, d);
        let to_light = position - p;
        let r = to_light.length() as f64;
        let cos_axis = (-to_light).normalize().dot(axis) as f64;
        albedo as f64 / PI
            * intensity as f64
            * spot_falloff(cos_axis, outer.cos() as f64, inner.cos() as f64)
            * (to_light.y as f64 / r)
            / (r * r)
    });
    // Compare where the spot lights the plane (the closed form is 0 outside the cone).
    let lit: Vec<usize> = (0..expected_full.len()).filter(|&i| expected_full[i] > 1e-3).collect();
    assert!(lit.len() > 200, "the spot must light a good part of the image ({} pixels)", lit.len());
    let expected: Vec<f64> = lit.iter().map(|&i| expected_full[i]).collect();
    assert_matches("spot light", &pick(&images, &lit), &expected, 2e-4);
    // Outside the outer cone: black.
    for i in 0..expected_full.len() {
        if expected_full[i] == 0.0 {
            assert!(images.iter().all(|img| img[i] == 0.0), "pixel {i} is outside the spot's cone");
        }
    }
}

/// Form factor from a differential area (normal +y) at the origin to the parallel rectangle
/// [0, a] x [0, b] at height h with a corner above it (Howell's catalogue, configuration B-3).
fn corner_form_factor(a: f64, b: f64, h: f64) -> f64 {
    let (x, y) = (a / h, b / h);
    let sx = (1.0 + x * x).sqrt();
    let sy = (1.0 + y * y).sqrt();
    (x / sx * (y / sx).atan() + y / sy * (x / sy).atan()) / (2.0 * PI)
}

/// Form factor to the rectangle [x0, x1] x [z0, z1] at height h, from a point at (px, pz),
/// by signed superposition of corner rectangles.
fn rect_form_factor(px: f64, pz: f64, x0: f64, x1: f64, z0: f64, z1: f64, h: f64) -> f64 {
    let g = |x: f64, z: f64| x.signum() * z.signum() * corner_form_factor(x.abs(), z.abs(), h);
    let (ax, bx, az, bz) = (x0 - px, x1 - px, z0 - pz, z1 - pz);
    g(bx, bz) - g(ax, bz) - g(bx, az) + g(ax, az)
}

#[test]
fn emissive_rectangle_over_diffuse_plane() {
    let albedo = 0.75;
    let le = 3.0;
    let h = 0.6;
    let (x0, x1, z0, z1) = (-0.5, 0.3, -0.2, 0.4);
    // A unit square in the y = 0 plane turned to face down (emitters are one-sided), scaled onto
    // the rectangle and lifted to height h.
    let light_transform = Mat4::from_translation(Vec3::new((x0 + x1) / 2.0, h, (z0 + z1) / 2.0))
        * Mat4::from_scale(Vec3::new((x1 - x0) / 2.0, 1.0, (z1 - z0) / 2.0))
        * Mat4::from_rotation_x(std::f32::consts::PI);
    // Camera beside the light, looking down at the plane under it.
    let camera = Camera {
        position: Vec3::new(0.0, 1.4, 1.6),
        target: Vec3::new(-0.1, 0.0, 0.0),
        up: Vec3::Y,
        vfov: 50f32.to_radians(),
    };
    let scene = SceneDesc {
        meshes: vec![Mesh::plane(50.0), Mesh::plane(1.0)],
        materials: vec![
            lambert(albedo),
            Material { base_color: Vec3::ZERO, emission: Vec3::splat(le), ..lambert(0.0) },
        ],
        instances: vec![
            Instance { mesh: 0, material: 0, transform: Mat4::IDENTITY },
            Instance { mesh: 1, material: 1, transform: light_transform },
        ],
        camera,
        ..Default::default()
    };
    let s = settings(1);
    let images = renders(&scene, s, 16, 11);
    let (x0, x1, z0, z1, hf) = (x0 as f64, x1 as f64, z0 as f64, z1 as f64, h as f64);
    let on_emitter = |o: Vec3, d: Vec3| {
        let t = (h - o.y) / d.y;
        let q = o + t * d;
        t > 0.0 && (x0..=x1).contains(&(q.x as f64)) && (z0..=z1).contains(&(q.z as f64))
    };
    // Pixels whose footprint straddles the emitter's outline measure coverage, not lighting:
    // compare the pixels wholly on the emitter or wholly on the plane. The camera is above the
    // emitter and sees its back face, which emits nothing and has a black base colour.
    let coverage = footprint_average(&camera, |o, d| on_emitter(o, d) as u32 as f64);
    let expected = footprint_average(&camera, |o, d| {
        let p = hit_ground(o, d);
        // Radiance of a Lambertian plane under a uniform emitter: albedo Le F(point -> rectangle).
        albedo as f64 * le as f64 * rect_form_factor(p.x as f64, p.z as f64, x0, x1, z0, z1, hf)
    });
    dump("rect", images[0].iter().cloned());
    dump("rect_expected", expected.iter().cloned());
    let emitter: Vec<usize> = (0..coverage.len()).filter(|&i| coverage[i] == 1.0).collect();
    assert!(emitter.len() > 20, "{} pixels see the emitter", emitter.len());
    for &i in &emitter {
        assert!(
            images.iter().all(|img| img[i].abs() < 1e-5),
            "pixel {i} sees the emitter's back face: {}",
            images[0][i]
        );
    }
    // Far from the rectangle the form factor is tiny and the relative noise huge: compare where
    // the plane receives at least 1% of the peak.
    let peak = (0..expected.len())
        .filter(|&i| coverage[i] == 0.0)
        .map(|i| expected[i])
        .fold(0.0, f64::max);
    let near: Vec<usize> =
        (0..expected.len()).filter(|&i| coverage[i] == 0.0 && expected[i] > 0.01 * peak).collect();
    assert!(near.len() > 300, "{} pixels", near.len());
    let e: Vec<f64> = near.iter().map(|&i| expected[i]).collect();
    let relative_error = assert_matches("emissive rectangle", &pick(&images, &near), &e, 5e-4);
    assert!(relative_error > 0.0, "area lights are sampled, so the estimate must be noisy");
}

/// The glTF metallic-roughness BRDF written out on the CPU (f64), independently of the WGSL:
/// c_diff / pi (1 - F(n.v)) (1 - F(n.l)) / (1 - F_avg) + F(v.h) D V with GGX D, Smith
/// height-correlated V and Schlick F (the diffuse coupling of Shirley et al. 1997).
fn gltf_brdf(m: &Material, n: glam::DVec3, wo: glam::DVec3, wi: glam::DVec3) -> glam::DVec3 {
    use glam::DVec3;
    let (nv, nl) = (n.dot(wo), n.dot(wi));
    if nv <= 0.0 || nl <= 0.0 {
        return DVec3::ZERO;
    }
    let base = m.base_color.as_dvec3();
    let metallic = m.metallic as f64;
    let alpha = (m.roughness as f64).powi(2).max(1e-3);
    let a2 = alpha * alpha;
    let f0 = DVec3::splat(0.04 * m.specular as f64).lerp(base, metallic);
    let f90 = m.specular as f64 + (1.0 - m.specular as f64) * metallic;
    let h = (wo + wi).normalize();
    let schlick = |c: f64| f0 + (DVec3::splat(f90) - f0) * (1.0 - c).clamp(0.0, 1.0).powi(5);
    let f = schlick(wo.dot(h));
    let f_avg = f0 + (DVec3::splat(f90) - f0) / 21.0;
    let coupling = (DVec3::ONE - schlick(nv)) * (DVec3::ONE - schlick(nl)) / (DVec3::ONE - f_avg);
    let nh = n.dot(h);
    let d = a2 / (PI * (nh * nh * (a2 - 1.0) + 1.0).powi(2));
    let v =
        0.5 / (nl * (nv * nv * (1.0 - a2) + a2).sqrt() + nv * (nl * nl * (1.0 - a2) + a2).sqrt());
    coupling * base * (1.0 - metallic) / PI + f * d * v
}

/// Directional albedo: the integral of f cos over the hemisphere above +y, by the midpoint rule
/// in (cos theta, phi).
fn directional_albedo(m: &Material, wo: glam::DVec3) -> glam::DVec3 {
    let n = glam::DVec3::Y;
    let (nu, nphi) = (384, 384);
    let mut sum = glam::DVec3::ZERO;
    for i in 0..nu {
        let cos_t = (i as f64 + 0.5) / nu as f64;
        let sin_t = (1.0 - cos_t * cos_t).sqrt();
        for j in 0..nphi {
            let phi = 2.0 * PI * (j as f64 + 0.5) / nphi as f64;
            let wi = glam::DVec3::new(sin_t * phi.cos(), cos_t, sin_t * phi.sin());
            sum += gltf_brdf(m, n, wo, wi) * cos_t;
        }
    }
    sum * (2.0 * PI / (nu * nphi) as f64)
}

#[test]
fn ggx_plane_under_constant_environment_matches_cpu_integral() {
    // A plane under a constant environment L = 1, direct lighting only: each pixel is the
    // directional albedo of the BRDF for its view direction. NEE (uniform sphere) and BSDF
    // sampling (GGX half vectors / cosine) are combined by MIS, so a wrong pdf or a sampling
    // routine that disagrees with its pdf shows up as bias. A distant camera with a narrow field
    // of view looks at the plane at about 60 degrees from the normal (Fresnel and masking matter).
    let camera = Camera {
        position: Vec3::new(60f32.to_radians().sin(), 60f32.to_radians().cos(), 0.0) * 40.0,
        target: Vec3::ZERO,
        up: Vec3::Y,
        vfov: 2f32.to_radians(),
    };
    let basis = CameraBasis::new(&camera, W, H);
    let materials = [
        Material {
            base_color: Vec3::new(0.9, 0.6, 0.3),
            metallic: 1.0,
            roughness: 0.5,
            ..Default::default()
        },
        Material {
            base_color: Vec3::new(0.2, 0.5, 0.8),
            metallic: 0.0,
            roughness: 0.3,
            ..Default::default()
        },
    ];
    for material in materials {
        let scene = SceneDesc {
            meshes: vec![Mesh::plane(50.0)],
            materials: vec![material],
            instances: vec![Instance { mesh: 0, material: 0, transform: Mat4::IDENTITY }],
            environment: Vec3::ONE,
            camera,
            ..Default::default()
        };
        let images = renders(&scene, settings(1), 16, 21);
        // The BRDF is isotropic, so the albedo depends only on the view angle; it is smooth, so
        // a table over the image's range of angles, linearly interpolated, stands for the pixels.
        let cos_view: Vec<f64> = (0..W * H)
            .map(|i| {
                -basis.ray_direction(Vec2::new((i % W) as f32 + 0.5, (i / W) as f32 + 0.5), W, H).y
                    as f64
            })
            .collect();
        let (lo, hi) =
            cos_view.iter().fold((f64::MAX, f64::MIN), |(a, b), &c| (a.min(c), b.max(c)));
        let table: Vec<f64> = (0..=16)
            .map(|k| {
                let c = lo + (hi - lo) * k as f64 / 16.0;
                directional_albedo(&material, glam::DVec3::new((1.0 - c * c).sqrt(), c, 0.0))
                    .element_sum()
                    / 3.0
            })
            .collect();
        let expected: Vec<f64> = cos_view
            .iter()
            .map(|&c| {
                let x = ((c - lo) / (hi - lo) * 16.0).clamp(0.0, 16.0);
                let k = (x.floor() as usize).min(15);
                table[k] + (table[k + 1] - table[k]) * (x - k as f64)
            })
            .collect();
        assert_matches(&format!("GGX {material:?}"), &images, &expected, 2e-3);
    }
}

fn small_scene() -> SceneDesc {
    let camera = Camera {
        position: Vec3::new(0.0, 1.2, 3.0),
        target: Vec3::new(0.0, 0.6, 0.0),
        up: Vec3::Y,
        vfov: 55f32.to_radians(),
    };
    SceneDesc {
        meshes: vec![Mesh::plane(2.0), sphere(16, 8), Mesh::plane(0.5)],
        materials: vec![
            Material { base_color: Vec3::new(0.7, 0.6, 0.5), roughness: 0.8, ..Default::default() },
            Material {
                base_color: Vec3::new(0.9, 0.5, 0.2),
                roughness: 0.5,
                metallic: 1.0,
                ..Default::default()
            },
            Material {
                base_color: Vec3::ZERO,
                emission: Vec3::new(3.0, 2.6, 2.2),
                ..Default::default()
            },
        ],
        instances: vec![
            Instance { mesh: 0, material: 0, transform: Mat4::IDENTITY },
            Instance {
                mesh: 1,
                material: 1,
                transform: Mat4::from_scale_rotation_translation(
                    Vec3::splat(0.5),
                    glam::Quat::IDENTITY,
                    Vec3::new(0.0, 0.5, 0.0),
                ),
            },
            Instance {
                mesh: 2,
                material: 2,
                transform: Mat4::from_rotation_translation(
                    glam::Quat::from_rotation_x(PI as f32),
                    Vec3::new(0.5, 1.5, 0.3),
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

#[test]
fn same_seed_same_bytes_other_seed_other_bytes() {
    let scene = small_scene();
    let s = settings(4);
    let a = render(&scene, s, 2, 42);
    let b = render(&scene, s, 2, 42);
    let c = render(&scene, s, 2, 43);
    let bytes = |o: &FrameOutput| bytemuck::cast_slice::<[f32; 4], u8>(&o.radiance).to_vec();
    assert_eq!(bytes(&a), bytes(&b), "same seed must give byte-identical radiance");
    assert_ne!(bytes(&a), bytes(&c), "another seed must give another image");
    assert_eq!(a.gbuffer, b.gbuffer);
    assert!(a.radiance.iter().all(|p| p.iter().all(|v| v.is_finite())), "radiance must be finite");
    assert_eq!(
        a.timings.iter().map(|t| t.pass.as_str()).collect::<Vec<_>>(),
        ["gbuffer", "path_trace"]
    );
    for t in &a.timings {
        assert!(t.ms > 0.0, "{t:?}");
        let clock = if gpu().has_timestamps() {
            render::timing::Clock::Gpu
        } else {
            render::timing::Clock::Wall
        };
        assert_eq!(t.clock, clock, "{t:?}");
    }
    // Every ray is counted: at least the G-buffer's and the camera rays of the 2 spp paths.
    assert!(
        a.rays >= 3 * a.radiance.len() as u64,
        "{} rays for {} pixels",
        a.rays,
        a.radiance.len()
    );
    assert_eq!(a.rays, b.rays, "the ray count is deterministic");
    assert_eq!(a.shaded, 2 * a.radiance.len() as u64);
}

#[test]
fn reference_is_stable_under_seed_change() {
    let scene = small_scene();
    let s = PathTracerSettings { width: 16, height: 12, max_depth: 6, rr_start_depth: 3 };
    let sg = SceneGpu::new(gpu(), &scene, s).unwrap();
    let mut pt = PathTracer::new(gpu(), &sg).unwrap();
    let spp = 16384;
    let mut calls = vec![];
    let a = pt
        .render_reference(gpu(), &sg, spp, 1, 0, &mut |done, total| calls.push((done, total)))
        .unwrap();
    assert_eq!(calls.last(), Some(&(spp, spp)));
    assert!(calls.windows(2).all(|w| w[0].0 < w[1].0), "progress must grow: {calls:?}");
    let b = pt.render_reference(gpu(), &sg, spp, 2, 0, &mut |_, _| {}).unwrap();
    let diff: f64 = a
        .iter()
        .zip(&b)
        .map(|(x, y)| (0..3).map(|c| (x[c] - y[c]).abs() as f64).sum::<f64>())
        .sum();
    let total: f64 = b.iter().map(|y| (0..3).map(|c| y[c] as f64).sum::<f64>()).sum();
    let rel = diff / total;
    assert!(rel < 0.01, "mean relative difference between two converged references: {rel:.4}");
    assert!(rel > 0.0, "different seeds must sample differently");
}

#[test]
fn reference_batches_sum_the_same_samples() {
    // 2 x 64 spp at 16 x 12 exceeds no batch limit; splitting into batches must give the same
    // samples (same sample indices), so the means agree to float summation order.
    let scene = small_scene();
    let s = PathTracerSettings { width: 16, height: 12, max_depth: 4, rr_start_depth: 2 };
    let sg = SceneGpu::new(gpu(), &scene, s).unwrap();
    let mut pt = PathTracer::new(gpu(), &sg).unwrap();
    let one = pt.render_reference(gpu(), &sg, 64, 9, 3, &mut |_, _| {}).unwrap();
    pt.set_paths_per_dispatch(gpu(), 16 * 12 * 16).unwrap();
    assert_eq!(pt.samples_per_dispatch(), 16);
    let mut batches = 0;
    let four = pt.render_reference(gpu(), &sg, 64, 9, 3, &mut |_, _| batches += 1).unwrap();
    assert_eq!(batches, 4);
    for (x, y) in one.iter().zip(&four) {
        for c in 0..3 {
            assert!((x[c] - y[c]).abs() <= 1e-5 * (1.0 + x[c].abs()), "{x:?} vs {y:?}");
        }
    }
}

#[test]
fn gbuffer_of_a_known_plane_and_motion_of_a_moved_instance() {
    let camera = top_down_camera(2.0);
    let texture = Texture {
        name: "grey".into(),
        width: 2,
        height: 2,
        rgba8: [188u8, 188, 188, 255].repeat(4),
    };
    let mut scene = SceneDesc {
        meshes: vec![Mesh::plane(1.0), Mesh::plane(0.25)],
        textures: vec![texture],
        materials: vec![
            Material { base_color: Vec3::new(0.2, 0.4, 0.6), specular: 0.0, ..Default::default() },
            Material { base_color: Vec3::ONE, base_color_texture: Some(0), ..Default::default() },
        ],
        instances: vec![
            Instance { mesh: 0, material: 0, transform: Mat4::IDENTITY },
            Instance {
                mesh: 1,
                material: 1,
                transform: Mat4::from_translation(Vec3::new(0.3, 0.5, 0.0)),
            },
        ],
        lights: vec![Light::Point { position: Vec3::new(0.0, 1.0, 0.0), intensity: Vec3::ONE }],
        camera,
        ..Default::default()
    };
    let s = settings(1);
    let mut sg = SceneGpu::new(gpu(), &scene, s).unwrap();
    let mut pt = PathTracer::new(gpu(), &sg).unwrap();
    let f0 = pt.render(gpu(), &sg, 1, 0, 0).unwrap();
    let basis = CameraBasis::new(&camera, W, H);
    let srgb_188 = ((188.0 / 255.0 + 0.055) / 1.055f64).powf(2.4);
    let mut counts = [0usize; 3];
    for y in 0..H {
        for x in 0..W {
            let i = (y * W + x) as usize;
            let g = &f0.gbuffer;
            let d = basis.ray_direction(Vec2::new(x as f32 + 0.5, y as f32 + 0.5), W, H);
            let ground = hit_ground(camera.position, d);
            match g.instance_id[i] {
                0 => {
                    counts[0] += 1;
                    let depth = (ground - camera.position).length();
                    assert!(
                        (g.depth[i] - depth).abs() < 1e-4 * depth,
                        "depth at ({x},{y}): {} vs {depth}",
                        g.depth[i]
                    );
                    assert!(
                        Vec3::from(g.normal[i]).abs_diff_eq(Vec3::Y, 1e-5),
                        "normal {:?}",
                        g.normal[i]
                    );
                    assert!(Vec3::from(g.albedo[i]).abs_diff_eq(Vec3::new(0.2, 0.4, 0.6), 1e-6));
                    assert!(g.primitive_id[i] < 2);
                    assert!(ground.x.abs() <= 1.0 + 1e-3 && ground.z.abs() <= 1.0 + 1e-3);
                }
                1 => {
                    counts[1] += 1;
                    let depth = (2.0 - 0.5) / d.dot(Vec3::NEG_Y);
                    assert!((g.depth[i] - depth).abs() < 1e-4 * depth);
                    for c in 0..3 {
                        assert!(
                            (g.albedo[i][c] as f64 - srgb_188).abs() < 2e-3,
                            "texture albedo {:?} vs {srgb_188}",
                            g.albedo[i]
                        );
                    }
                }
                NO_HIT => {
                    counts[2] += 1;
                    assert_eq!(g.depth[i], f32::INFINITY);
                    assert_eq!(g.primitive_id[i], NO_HIT);
                    assert!(
                        ground.x.abs() >= 1.0 - 1e-3 || ground.z.abs() >= 1.0 - 1e-3,
                        "pixel ({x},{y}) should see the plane"
                    );
                }
                other => panic!("instance id {other}"),
            }
            // Nothing moved yet: no motion.
            assert_eq!(g.motion[i], [0.0, 0.0], "first frame motion at ({x},{y})");
        }
    }
    assert!(counts.iter().all(|&c| c > 20), "plane / quad / miss pixels: {counts:?}");

    // Frame 1: the quad moves by delta; its pixels must point back to where it was.
    let delta = Vec3::new(0.2, 0.0, -0.1);
    scene.instances[1].transform = Mat4::from_translation(Vec3::new(0.3, 0.5, 0.0) + delta);
    sg.update(gpu(), &scene);
    let f1 = pt.render(gpu(), &sg, 1, 0, 1).unwrap();
    let mut moved = 0;
    for i in 0..(W * H) as usize {
        let g = &f1.gbuffer;
        let (x, y) = (i as u32 % W, i as u32 / W);
        let d = basis.ray_direction(Vec2::new(x as f32 + 0.5, y as f32 + 0.5), W, H);
        let p = camera.position + d * g.depth[i];
        let expected = match g.instance_id[i] {
            1 => {
                moved += 1;
                basis.project(p - delta, W, H).unwrap() - basis.project(p, W, H).unwrap()
            }
            _ => Vec2::ZERO,
        };
        assert!(
            Vec2::from(g.motion[i]).abs_diff_eq(expected, 2e-3),
            "motion at ({x},{y}): {:?} vs {expected}",
            g.motion[i]
        );
    }
    assert!(moved > 20);

    // Frame 2: the camera moves; static plane points move by the reprojection.
    let mut moved_camera = camera;
    moved_camera.position += Vec3::new(0.1, 0.2, 0.05);
    moved_camera.target += Vec3::new(0.1, 0.0, 0.05);
    scene.camera = moved_camera;
    sg.update(gpu(), &scene); // the quad stays where frame 1 had it
    let f2 = pt.render(gpu(), &sg, 1, 0, 2).unwrap();
    let now = CameraBasis::new(&moved_camera, W, H);
    let mut checked = 0;
    for i in 0..(W * H) as usize {
        let g = &f2.gbuffer;
        if g.instance_id[i] != 0 {
            continue;
        }
        let (x, y) = (i as u32 % W, i as u32 / W);
        let centre = Vec2::new(x as f32 + 0.5, y as f32 + 0.5);
        let p = moved_camera.position + now.ray_direction(centre, W, H) * g.depth[i];
        let expected = basis.project(p, W, H).unwrap() - centre;
        assert!(
            Vec2::from(g.motion[i]).abs_diff_eq(expected, 5e-3),
            "camera motion at ({x},{y}): {:?} vs {expected}",
            g.motion[i]
        );
        checked += 1;
    }
    assert!(checked > 100);
}

#[test]
fn bad_settings_and_scenes_are_refused() {
    let scene = ground_scene(0.5, top_down_camera(2.0));
    let huge = gpu().limits.max_texture_dimension_2d + 1;
    let err = SceneGpu::new(
        gpu(),
        &scene,
        PathTracerSettings { width: huge, height: 4, max_depth: 1, rr_start_depth: 1 },
    )
    .err()
    .expect("oversize refused")
    .to_string();
    assert!(err.contains("image width"), "{err}");
    let err = SceneGpu::new(gpu(), &scene, PathTracerSettings { max_depth: 0, ..settings(1) })
        .err()
        .expect("depth 0 refused")
        .to_string();
    assert!(err.contains("max_depth"), "{err}");
    let mut bad = scene.clone();
    bad.materials[0].base_color_texture = Some(3);
    let err = SceneGpu::new(gpu(), &bad, settings(1))
        .err()
        .expect("dangling texture refused")
        .to_string();
    assert!(err.contains("texture 3"), "{err}");
}
