//! Media in the path tracer (media::gpu::VolumePathPass) against closed forms and against each
//! other in expectation. Statistics: each image carries the variance of every pixel's mean
//! (from its own samples); two images are compared by z = Σ(a − b) / sqrt(Σ(var_a + var_b))
//! over all pixels (|z| ≤ 4.5) and per pixel (≤ 6 standard errors, plus a float allowance).
//!
//! - An absorbing homogeneous slab (albedo 0) between the camera and a lit ground: the image is
//!   the path tracer's image times exp(−σ_t ℓ_camera) exp(−σ_t ℓ_light), ℓ the slab's chord
//!   along the camera ray (averaged over each pixel's footprint) and along the shadow ray.
//! - A scattering cloud around a point light (direct light): shadow rays by ratio tracking and by the
//!   track-length estimate (delta tracking) agree in expectation; so do free-flight sampling
//!   alone and its MIS with equiangular sampling by Eq. 9 with the naive, jackknife and Miller
//!   weights (all unbiased).

use std::sync::OnceLock;

use glam::{Mat4, UVec3, Vec2, Vec3};
use media::gpu::{Combination, GpuMedium, MisWeight, ShadowTransmittance, VolumeImage, VolumePathPass, VolumePathSettings};
use media::{DensityGrid, DensityKind, Medium};
use render::frame::CameraBasis;
use render::gpu::Gpu;
use render::path_tracer::{PathTracer, PathTracerSettings};
use render::scene::{Camera, Instance, Light, Material, Mesh, SceneDesc};

const W: u32 = 32;
const H: u32 = 18;

fn gpu() -> &'static Gpu {
    static GPU: OnceLock<Gpu> = OnceLock::new();
    GPU.get_or_init(|| Gpu::new().expect("a wgpu adapter (lavapipe on CI)"))
}

fn ground(camera: Camera, lights: Vec<Light>) -> SceneDesc {
    SceneDesc {
        meshes: vec![Mesh::plane(50.0)],
        materials: vec![Material { base_color: Vec3::splat(0.5), specular: 0.0, ..Default::default() }],
        instances: vec![Instance { mesh: 0, material: 0, transform: Mat4::IDENTITY }],
        lights,
        camera,
        ..Default::default()
    }
}

fn medium(kind: DensityKind, res: u32, sigma_t: f32, lo: Vec3, hi: Vec3) -> GpuMedium {
    GpuMedium::new(gpu(), &Medium::new(DensityGrid::bake(&kind, UVec3::splat(res), sigma_t, lo, hi)))
}

fn lum(c: &[f32; 3]) -> f64 {
    0.2126 * f64::from(c[0]) + 0.7152 * f64::from(c[1]) + 0.0722 * f64::from(c[2])
}

/// (z over all pixels, worst per-pixel |a − b| in standard errors) of `a` against `b`, whose
/// variances (`var_b`) may be zero (an exact image).
fn compare(a: &VolumeImage, b: &[f64], var_b: &[f64]) -> (f64, f64) {
    let (mut diff, mut var, mut worst) = (0.0, 0.0, 0f64);
    for (i, m) in a.mean.iter().enumerate() {
        let (d, v) = (lum(m) - b[i], a.var_of_mean[i] + var_b[i]);
        diff += d;
        var += v;
        worst = worst.max(d.abs() / (v.sqrt() + 1e-6 * b[i].abs() + 1e-9));
    }
    (diff / var.sqrt(), worst)
}

#[test]
fn absorbing_slab_attenuates_the_path_tracer_image_by_its_closed_form() {
    let sigma = 0.6;
    let camera = Camera { position: Vec3::new(0.0, 4.0, 0.0), target: Vec3::ZERO, up: Vec3::NEG_Z, vfov: 50f32.to_radians() };
    // Straight down: the shadow ray's chord through the slab y in [1, 2] is 1.
    let sun = Light::Directional { direction: Vec3::NEG_Y, irradiance: Vec3::splat(2.0), angular_radius: 0.0 };
    let scene = ground(camera, vec![sun]);
    let settings = PathTracerSettings { width: W, height: H, max_depth: 1, rr_start_depth: 8 };
    let mut tracer = PathTracer::new(gpu(), &scene, settings).expect("path tracer");
    let plain = tracer.render(gpu(), 4, 3, 0).expect("render").radiance;
    let slab = medium(DensityKind::Homogeneous, 8, sigma, Vec3::new(-60.0, 1.0, -60.0), Vec3::new(60.0, 2.0, 60.0));
    let pass = VolumePathPass::new(gpu(), &tracer, &slab).expect("volume path pass compiles");
    let image = pass.render(gpu(), &tracer, &slab, Vec3::ZERO, &VolumePathSettings::default(), 128, 5, 0).expect("render");
    // exp(−σ ℓ) over each pixel's footprint (16 x 16 points), ℓ = 1 / |d.y| through the slab.
    let basis = CameraBasis::new(&camera, W, H);
    let k = 16;
    let expected: Vec<f64> = (0..W * H)
        .map(|i| {
            let (x, y) = (i % W, i / W);
            let mut sum = 0.0;
            for j in 0..k {
                for s in 0..k {
                    let p = Vec2::new(x as f32 + (s as f32 + 0.5) / k as f32, y as f32 + (j as f32 + 0.5) / k as f32);
                    sum += (-f64::from(sigma) / f64::from(basis.ray_direction(p, W, H).y.abs())).exp();
                }
            }
            let plain = lum(&[plain[i as usize][0], plain[i as usize][1], plain[i as usize][2]]);
            plain * (-f64::from(sigma)).exp() * sum / f64::from(k * k)
        })
        .collect();
    let (z, worst) = compare(&image, &expected, &vec![0.0; expected.len()]);
    let mean = image.mean.iter().map(lum).sum::<f64>() / expected.len() as f64;
    let want = expected.iter().sum::<f64>() / expected.len() as f64;
    println!("absorbing slab: mean {mean:.5} expected {want:.5}, z = {z:.2}, worst pixel {worst:.2} SE");
    assert!(z.abs() <= 4.5 && worst <= 6.0, "absorbing slab: z = {z}, worst pixel {worst} SE");
}

/// A point light inside a cloud over the ground, just above the view (no camera ray passes
/// through it: a pixel whose rays pass arbitrarily close has a heavy-tailed estimate, and the
/// per-pixel variances the comparisons use would not be reliable there).
fn cloud_scene() -> (SceneDesc, GpuMedium) {
    let camera = Camera { position: Vec3::new(0.0, 1.0, 3.5), target: Vec3::new(0.0, 0.8, 0.0), up: Vec3::Y, vfov: 40f32.to_radians() };
    let light = Light::Point { position: Vec3::new(0.0, 2.3, 0.0), intensity: Vec3::splat(3.0) };
    let cloud = medium(DensityKind::Cloud { octaves: 3, frequency: 2.0, seed: 5 }, 32, 3.0, Vec3::new(-1.0, 0.0, -1.0), Vec3::new(1.0, 3.0, 1.0));
    (ground(camera, vec![light]), cloud)
}

fn render_cloud(tracer: &PathTracer, pass: &VolumePathPass, cloud: &GpuMedium, s: VolumePathSettings, seed: u64) -> VolumeImage {
    pass.render(gpu(), tracer, cloud, Vec3::splat(0.8), &s, 256, seed, 0).expect("render")
}

fn agree(what: &str, a: &VolumeImage, b: &VolumeImage) {
    let (z, worst) = compare(a, &b.mean.iter().map(lum).collect::<Vec<_>>(), &b.var_of_mean);
    let (ma, mb) = (a.mean.iter().map(lum).sum::<f64>(), b.mean.iter().map(lum).sum::<f64>());
    println!("{what}: mean {:.5} vs {:.5}, z = {z:.2}, worst pixel {worst:.2} SE", ma / a.mean.len() as f64, mb / b.mean.len() as f64);
    assert!(z.abs() <= 4.5 && worst <= 6.0, "{what}: z = {z}, worst pixel {worst} SE");
}

#[test]
fn shadow_ratio_tracking_equals_delta_tracking_and_mis_is_unbiased_in_a_cloud() {
    let (scene, cloud) = cloud_scene();
    // Direct light (max depth 1): single scattering in the medium and the lit ground, each shadow
    // ray through the cloud; deeper paths start segments next to the light, whose estimates are
    // heavy-tailed for every strategy.
    let tracer = PathTracer::new(gpu(), &scene, PathTracerSettings { width: W, height: H, max_depth: 1, rr_start_depth: 2 }).expect("path tracer");
    let pass = VolumePathPass::new(gpu(), &tracer, &cloud).expect("volume path pass compiles");
    let base = VolumePathSettings::default();
    let ratio = render_cloud(&tracer, &pass, &cloud, base, 11);
    let track = render_cloud(&tracer, &pass, &cloud, VolumePathSettings { shadow: ShadowTransmittance::TrackLength, ..base }, 12);
    agree("shadow rays: ratio tracking vs track-length", &ratio, &track);
    let mean_var = |im: &VolumeImage| im.var_of_mean.iter().sum::<f64>() / im.var_of_mean.len() as f64;
    println!("mean variance of a pixel's mean: free-flight only {:.3e}", mean_var(&ratio));
    for mis in [MisWeight::Naive, MisWeight::Jackknife, MisWeight::Miller] {
        let im = render_cloud(&tracer, &pass, &cloud, VolumePathSettings { mis, combination: Combination::Eq9, ..base }, 13);
        println!("{mis:?} Eq. 9: mean variance {:.3e}", mean_var(&im));
        agree(&format!("{mis:?} Eq. 9 vs free-flight only"), &im, &ratio);
    }
}
