//! The GPU random walk (media::gpu::SubsurfacePathPass, the random-walk reference of the SSS
//! scenarios) against the half-space values of the CPU walk's theory (random_walk.rs):
//! Chandrasekhar's reflection of a semi-infinite isotropic medium under a normally incident
//! beam of irradiance E, seen at cosine μ from the normal,
//!   L(μ) = E α H(μ) H(1) / (4π (μ + 1)),
//! with the H-function of `random_walk::h_function` (tested there against the CPU walk).
//!
//! The half-space is a slab 200 mean free paths deep and 400 wide under a directional light
//! from straight above, seen from above (μ from 0.87 to 1 over the image). Each channel has its
//! own albedo A = (0.3, 0.6, 0.8) and a dmfp chosen so that σ_t = 10 per unit; α comes from
//! the published mapping (scene::SubsurfaceMedium, Chiang et al. 2016), written here as numbers
//! computed by hand from the formula (0.75579, 0.95259, 0.99009), so a broken mapping fails as
//! a broken walk does. Bound: Monte Carlo error at the sample count: the luminance summed over
//! the image within 4.5 standard errors (its variance the sum of the pixels' sample variances
//! of the mean), and every pixel within 6.

mod support;

use glam::{Mat4, Vec2, Vec3};
use media::gpu::SubsurfacePathPass;
use render::frame::CameraBasis;
use render::frame_bindings::FrameBindings;
use render::path_tracer::PathTracerSettings;
use render::scene::{Camera, Instance, Light, Material, SceneDesc};
use render::scene_gpu::SceneGpu;
use scene::Subsurface;
use support::random_walk::h_function;
use testkit::test_scenes::{box_mesh, gpu};

const W: u32 = 24;
const H: u32 = 16;
const E: f32 = 2.0;
/// α of A = 0.3, 0.6, 0.8 by Chiang et al.'s α = 1 − exp(−5.09406 A + 2.61188 A² − 4.31805 A³).
const ALPHA: [f64; 3] = [0.755_792_291, 0.952_586_961, 0.990_092_730];
const ALBEDO: [f32; 3] = [0.3, 0.6, 0.8];
/// Θ3(A) / s(A) / 10 per channel: ℓ_d giving σ_t = s_Θ3 / (ℓ_d s_mfp) = 10.
const DMFP: [f32; 3] = [0.141_417_41, 0.279_961_18, 0.761_789_2];

fn camera() -> Camera {
    Camera {
        position: Vec3::new(0.0, 3.0, 0.0),
        target: Vec3::ZERO,
        up: Vec3::NEG_Z,
        vfov: 40f32.to_radians(),
    }
}

fn slab() -> SceneDesc {
    SceneDesc {
        meshes: vec![box_mesh(false)],
        materials: vec![Material {
            base_color: Vec3::from_array(ALBEDO),
            specular: 0.0,
            subsurface: Some(Subsurface { dmfp: Vec3::from_array(DMFP) }),
            ..Default::default()
        }],
        instances: vec![Instance {
            mesh: 0,
            material: 0,
            transform: Mat4::from_translation(Vec3::new(0.0, -10.0, 0.0))
                * Mat4::from_scale(Vec3::new(20.0, 10.0, 20.0)),
        }],
        lights: vec![Light::Directional {
            direction: Vec3::NEG_Y,
            irradiance: Vec3::splat(E),
            angular_radius: 0.0,
        }],
        camera: camera(),
        ..Default::default()
    }
}

fn lum(c: [f64; 3]) -> f64 {
    0.2126 * c[0] + 0.7152 * c[1] + 0.0722 * c[2]
}

/// Chandrasekhar's L(μ) per channel, averaged over each pixel's footprint (8 x 8 points).
fn expected() -> Vec<f64> {
    let basis = CameraBasis::new(&camera(), W, H);
    let h1 = ALPHA.map(|a| h_function(a, 1.0));
    let k = 8;
    (0..W * H)
        .map(|i| {
            let mut sum = 0.0;
            for j in 0..k * k {
                let p = Vec2::new(
                    (i % W) as f32 + ((j % k) as f32 + 0.5) / k as f32,
                    (i / W) as f32 + ((j / k) as f32 + 0.5) / k as f32,
                );
                let mu = f64::from(-basis.ray_direction(p, W, H).y);
                let c = [0, 1, 2].map(|c| {
                    f64::from(E) * ALPHA[c] * h_function(ALPHA[c], mu) * h1[c]
                        / (4.0 * std::f64::consts::PI * (mu + 1.0))
                });
                sum += lum(c);
            }
            sum / f64::from(k * k)
        })
        .collect()
}

#[test]
fn the_gpu_walk_reflects_a_half_space_as_chandrasekhar() {
    let desc = slab();
    let settings = PathTracerSettings { width: W, height: H, max_depth: 2, rr_start_depth: 3 };
    let scene = SceneGpu::new(gpu(), &desc, settings).expect("scene");
    let bindings = FrameBindings::new(gpu(), &scene);
    let pass = SubsurfacePathPass::new(gpu(), &scene).expect("pass");
    let image = pass.render(gpu(), &scene, &bindings, &desc.materials, 64, 7, 0).expect("render");
    let truth = expected();
    let (mut diff, mut var, mut worst) = (0.0, 0.0, 0f64);
    for (i, m) in image.mean.iter().enumerate() {
        let d = lum(m.map(f64::from)) - truth[i];
        diff += d;
        var += image.var_of_mean[i];
        worst = worst.max(d.abs() / image.var_of_mean[i].sqrt().max(1e-9));
    }
    let z = diff / var.sqrt();
    let mean_truth = truth.iter().sum::<f64>() / truth.len() as f64;
    let mean_gpu = diff / truth.len() as f64 + mean_truth;
    println!(
        "mean luminance GPU {mean_gpu:.5} vs Chandrasekhar {mean_truth:.5}: z = {z:.2}, worst pixel {worst:.2} standard errors"
    );
    assert!(z.abs() <= 4.5, "image sum off by {z:.2} standard errors");
    assert!(worst <= 6.0, "a pixel off by {worst:.2} standard errors");
}

#[test]
fn a_material_outside_the_mapping_is_refused() {
    let mut desc = slab();
    desc.materials[0].base_color = Vec3::new(1.2, 0.5, 0.5);
    let err = media::gpu::coefficient_table(&desc.materials).unwrap_err();
    assert!(err.contains("[0, 1]"), "{err}");
}
