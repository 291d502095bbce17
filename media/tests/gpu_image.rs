//! Primary-ray transmittance images through the whole GPU path (camera rays clipped to the
//! medium's box in WGSL, one estimator, per-pixel reduction): a homogeneous slab gives
//! exp(−σ_t d) in every pixel, and a cloud's image equals the CPU reference's estimate for
//! estimate on the same random numbers.

mod common;

use std::sync::OnceLock;

use common::all_estimators;
use glam::{UVec3, Vec3};
use media::gpu::{GpuMedium, ImagePass};
use media::image::{ImageKey, directions, estimates, exact, reduce};
use media::{DensityGrid, DensityKind, Estimator, Medium};
use render::frame::CameraBasis;
use render::gpu::Gpu;
use render::scene::Camera;

fn gpu() -> &'static Gpu {
    static GPU: OnceLock<Gpu> = OnceLock::new();
    GPU.get_or_init(|| Gpu::new().expect("a wgpu adapter (lavapipe on CI)"))
}

const W: u32 = 32;
const H: u32 = 18;

fn camera(position: Vec3) -> CameraBasis {
    CameraBasis::new(
        &Camera { position, target: Vec3::ZERO, up: Vec3::Y, vfov: 40f32.to_radians() },
        W,
        H,
    )
}

#[test]
fn homogeneous_slab_image_is_exp_minus_sigma_t_d() {
    let sigma_t = 0.8;
    // A slab 1 deep in z, wide enough that every camera ray crosses its whole depth.
    let medium = Medium::new(DensityGrid::bake(
        &DensityKind::Homogeneous,
        UVec3::new(32, 32, 8),
        sigma_t,
        Vec3::new(-20.0, -20.0, -0.5),
        Vec3::new(20.0, 20.0, 0.5),
    ));
    let cam = camera(Vec3::new(0.0, 0.0, -3.0));
    let dirs = directions(&cam, W, H);
    let gm = GpuMedium::new(gpu(), &medium);
    let pass = ImagePass::new(gpu(), &gm).expect("media image pass compiles");
    let key = ImageKey { seed: 5, frame: 0, spp: 64 };
    for est in all_estimators() {
        let (got, timings) = pass.run(gpu(), &gm, cam.position, &dirs, W, est, key).expect("image");
        assert_eq!(timings.len(), 1);
        let stats = reduce(&got, key.spp);
        let mut worst = 0.0f32;
        for (p, d) in dirs.iter().enumerate() {
            let want = (-sigma_t * (1.0 / d.z)).exp();
            let se = stats.std[p] / (key.spp as f32).sqrt();
            let z = (stats.mean[p] - want).abs() / (se + 2e-5);
            worst = worst.max(z);
        }
        // 576 pixels: 5 SE leaves a false failure below 1 in 3000 runs.
        assert!(worst <= 5.0, "{}: the worst pixel is {worst} SE from exp(-σ_t d)", est.label());
    }
}

#[test]
fn cloud_image_matches_the_cpu_reference_estimate_for_estimate() {
    let medium = Medium::new(DensityGrid::bake(
        &DensityKind::Cloud { octaves: 4, frequency: 3.0, seed: 7 },
        UVec3::splat(48),
        6.0,
        Vec3::splat(-1.0),
        Vec3::splat(1.0),
    ));
    let cam = camera(Vec3::new(0.3, 0.4, -3.0));
    let dirs = directions(&cam, W, H);
    let gm = GpuMedium::new(gpu(), &medium);
    let pass = ImagePass::new(gpu(), &gm).expect("media image pass compiles");
    let key = ImageKey { seed: 9, frame: 3, spp: 4 };
    let reference = exact(&medium, cam.position, &dirs);
    assert!(
        reference.iter().any(|&t| t < 0.5) && reference.contains(&1.0),
        "the image must show the cloud and empty space"
    );
    for est in [
        Estimator::Jackknife { samples: 8 },
        Estimator::JackknifeTied { step: 0.3 },
        Estimator::UnbiasedRayMarching { multiplier: 1.0 },
        Estimator::TrackLength,
    ] {
        let (got, _) = pass.run(gpu(), &gm, cam.position, &dirs, W, est, key).expect("image");
        let want = estimates(&medium, cam.position, &dirs, est, key);
        let differ = got
            .iter()
            .zip(&want)
            .filter(|(g, w)| {
                (g.value - w.value).abs() > 1e-4 + 1e-3 * w.value.abs() || g.lookups != w.lookups
            })
            .count();
        assert!(
            differ * 100 <= got.len(),
            "{}: {differ} of {} estimates differ",
            est.label(),
            got.len()
        );
    }
}
