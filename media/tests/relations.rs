//! The paper's relations on the cloud, through the GPU image pass (32x18 primary rays), over
//! three seeds; each margin comes from the spread of the per-seed values (Student t with 2
//! degrees of freedom), never from a constant tuned to one run:
//! - the jackknife's bias is at most half the naive exp(−X̄)'s at equal mN (one-sided, paired);
//! - track-length's per-pixel variance is (1 − T)T (two-sided, within noise);
//! - ratio tracking and unbiased ray marching are unbiased (two-sided, within noise: the
//!   standard error from the per-pixel sample variances over all seeds, not from 3 seed means).
//!
//! The exact T is regular tracking (exact for nearest-neighbour voxels).
//!
//! Bias per image is the RMS over pixels of the noise-corrected bias: per pixel
//! (mean − T)² − s²/spp is an unbiased estimate of bias², so the relation does not drown in the
//! noise of the mean as a plain mean |mean − T| would at lavapipe's sample counts (departure:
//! the paper reports mean |bias| from 2^18 spp).

use std::sync::OnceLock;

use glam::{UVec3, Vec3};
use media::gpu::{GpuMedium, ImagePass};
use media::image::{ImageKey, PixelStats, directions, exact, reduce, rms_bias};
use media::{DensityGrid, DensityKind, Estimator, Medium};
use render::frame::CameraBasis;
use render::gpu::Gpu;
use render::scene::Camera;

const W: u32 = 32;
const H: u32 = 18;
const SEEDS: [u32; 3] = [1, 2, 3];
/// Student t quantiles for 2 degrees of freedom: one-sided 95%, two-sided 99%.
const T_ONE_SIDED_95: f64 = 2.920;
const T_TWO_SIDED_99: f64 = 9.925;

fn gpu() -> &'static Gpu {
    static GPU: OnceLock<Gpu> = OnceLock::new();
    GPU.get_or_init(|| Gpu::new().expect("a wgpu adapter (lavapipe on CI)"))
}

struct Setup {
    gpu_medium: GpuMedium,
    pass: ImagePass,
    camera: CameraBasis,
    dirs: Vec<Vec3>,
    exact: Vec<f32>,
}

fn setup() -> &'static Setup {
    static SETUP: OnceLock<Setup> = OnceLock::new();
    SETUP.get_or_init(|| {
        let medium = Medium::new(DensityGrid::bake(
            &DensityKind::Cloud { octaves: 5, frequency: 3.0, seed: 7 },
            UVec3::splat(96),
            6.0,
            Vec3::splat(-1.0),
            Vec3::splat(1.0),
        ));
        let camera = CameraBasis::new(
            &Camera {
                position: Vec3::new(0.0, 0.3, -3.5),
                target: Vec3::ZERO,
                up: Vec3::Y,
                vfov: 40f32.to_radians(),
            },
            W,
            H,
        );
        let dirs = directions(&camera, W, H);
        let exact = exact(&medium, camera.position, &dirs);
        let gpu_medium = GpuMedium::new(gpu(), &medium);
        let pass = ImagePass::new(gpu(), &gpu_medium).expect("media image pass compiles");
        Setup { gpu_medium, pass, camera, dirs, exact }
    })
}

fn image(est: Estimator, seed: u32, spp: u32) -> PixelStats {
    // One pass at a time: the pass's timestamp buffer is mapped after each run.
    static LOCK: std::sync::Mutex<()> = std::sync::Mutex::new(());
    let _one = LOCK.lock().unwrap_or_else(|e| e.into_inner());
    let s = setup();
    let (e, _) = s
        .pass
        .run(
            gpu(),
            &s.gpu_medium,
            s.camera.position,
            &s.dirs,
            W,
            est,
            ImageKey { seed, frame: 0, spp },
        )
        .expect("image");
    reduce(&e, spp)
}

/// Mean and standard error of per-seed values.
fn mean_se(v: &[f64]) -> (f64, f64) {
    let n = v.len() as f64;
    let m = v.iter().sum::<f64>() / n;
    let var = v.iter().map(|x| (x - m).powi(2)).sum::<f64>() / (n - 1.0);
    (m, (var / n).sqrt())
}

#[test]
fn jackknife_bias_is_at_most_half_the_naive_bias_at_equal_mn() {
    let s = setup();
    let spp = 4096;
    let margins: Vec<f64> = SEEDS
        .iter()
        .map(|&seed| {
            let jack =
                rms_bias(&image(Estimator::Jackknife { samples: 4 }, seed, spp), &s.exact, spp);
            let naive = rms_bias(&image(Estimator::Naive { samples: 8 }, seed, spp), &s.exact, spp);
            println!("seed {seed}: RMS bias jackknife {jack:.5}, naive {naive:.5}");
            0.5 * naive - jack
        })
        .collect();
    let (m, se) = mean_se(&margins);
    assert!(
        m > T_ONE_SIDED_95 * se,
        "half the naive bias minus the jackknife's: {m} ± {se} over seeds {margins:?}"
    );
}

#[test]
fn track_length_variance_is_one_minus_t_times_t() {
    let s = setup();
    let spp = 1024;
    let diffs: Vec<f64> = SEEDS
        .iter()
        .map(|&seed| {
            let img = image(Estimator::TrackLength, seed, spp);
            img.std
                .iter()
                .zip(&s.exact)
                .map(|(sd, &t)| f64::from(*sd).powi(2) - f64::from((1.0 - t) * t))
                .sum::<f64>()
                / s.exact.len() as f64
        })
        .collect();
    let mean_var =
        s.exact.iter().map(|&t| f64::from((1.0 - t) * t)).sum::<f64>() / s.exact.len() as f64;
    let (m, se) = mean_se(&diffs);
    println!("mean (s² − (1−T)T) {m:.6} ± {se:.6}; mean (1−T)T {mean_var:.4}");
    let partial = s.exact.iter().filter(|&&t| (0.1..0.9).contains(&t)).count();
    assert!(partial >= 20, "the cloud must have pixels of intermediate transmittance: {partial}");
    assert!(
        m.abs() <= T_TWO_SIDED_99 * se,
        "track-length variance differs from (1−T)T by {m} ± {se} over seeds {diffs:?}"
    );
}

/// The mean bias over pixels and seeds, and its standard error from the per-pixel sample
/// variances: every estimate (seed, pixel, sample) is independent, so the mean over all of them
/// is normal with variance Σ s²/spp over pixels and seeds, divided by the count of pixels and
/// seeds squared. Hundreds of thousands of estimates: the normal quantile, no t with 2 df.
fn mean_bias_and_se(est: Estimator, spp: u32) -> (f64, f64) {
    let s = setup();
    let (mut bias, mut var) = (0.0, 0.0);
    for &seed in &SEEDS {
        let img = image(est, seed, spp);
        for ((m, sd), t) in img.mean.iter().zip(&img.std).zip(&s.exact) {
            bias += f64::from(m - t);
            var += f64::from(*sd).powi(2) / f64::from(spp);
        }
    }
    let n = (SEEDS.len() * s.exact.len()) as f64;
    (bias / n, var.sqrt() / n)
}

/// Two-sided 99.9% quantile of the standard normal.
const Z_TWO_SIDED_999: f64 = 3.2905;

#[test]
fn ratio_tracking_and_unbiased_ray_marching_are_unbiased() {
    let spp = 128;
    for est in [Estimator::RatioTracking, Estimator::UnbiasedRayMarching { multiplier: 1.0 }] {
        let (m, se) = mean_bias_and_se(est, spp);
        println!("{}: mean bias {m:.6} ± {se:.6} (z = {:.2})", est.label(), m / se);
        assert!(
            m.abs() <= Z_TWO_SIDED_999 * se,
            "{}: mean bias {m} is {:.1} standard errors ({se}) from 0",
            est.label(),
            m / se
        );
    }
    // The test can tell: the naive estimate's bias at few samples is outside the same bound.
    let (m, se) = mean_bias_and_se(Estimator::Naive { samples: 2 }, spp);
    assert!(
        m.abs() > Z_TWO_SIDED_999 * se,
        "naive with 2 samples should be visibly biased: {m} ± {se}"
    );
}
