//! Every transmittance estimator on baked media against the exact transmittance of regular
//! tracking (nearest-neighbour voxels make it exact): a homogeneous slab gives exp(−σ_t d); the
//! unbiased estimators stay within noise on a cloud; track-length's std is sqrt((1 − T)T); the
//! jackknife has less bias than the naive exp(−X̄) at equal mN; Sec. 4.1's stratified jittered
//! sampling converges near 1/N (Fig. 5). Margins are standard errors of the same run.

mod common;

use common::{Moments, all_estimators};
use glam::{UVec3, Vec3};
use media::regular_tracking::optical_depth;
use media::stratified::{iid_uniform, stratified_jittered};
use media::{DensityGrid, DensityKind, Estimator, Medium, Pcg, Segment};

const Z: f64 = 4.5;

fn cloud(res: u32) -> Medium {
    let kind = DensityKind::Cloud { octaves: 4, frequency: 3.0, seed: 7 };
    Medium::new(DensityGrid::bake(
        &kind,
        UVec3::splat(res),
        8.0,
        Vec3::splat(-1.0),
        Vec3::splat(1.0),
    ))
}

/// Rays through the cloud, from a camera in front of it, spread over its face.
fn cloud_rays(medium: &Medium, n: usize) -> Vec<Segment> {
    let eye = Vec3::new(0.0, 0.0, -4.0);
    (0..n)
        .filter_map(|i| {
            let a = i as f32 / n as f32;
            let target = Vec3::new(
                1.2 * (a * std::f32::consts::TAU * 3.0).cos() * a,
                1.2 * (a * std::f32::consts::TAU * 3.0).sin() * a,
                0.0,
            );
            medium.segment(eye, (target - eye).normalize(), 100.0)
        })
        .collect()
}

fn mean_of(est: Estimator, medium: &Medium, seg: &Segment, trials: usize, seed: u32) -> Moments {
    let mut rng = Pcg::new(seed);
    let mut m = Moments::default();
    for _ in 0..trials {
        m.add(f64::from(est.estimate(medium, seg, &mut rng).value));
    }
    m
}

#[test]
fn homogeneous_slab_matches_exp_minus_sigma_t_d() {
    let sigma_t = 1.5;
    let medium = Medium::new(DensityGrid::bake(
        &DensityKind::Homogeneous,
        UVec3::new(40, 40, 20),
        sigma_t,
        Vec3::new(-2.0, -2.0, 0.0),
        Vec3::new(2.0, 2.0, 1.0),
    ));
    // A slanted ray: d = 1 / cos θ through the slab of depth 1.
    let dir = Vec3::new(0.3, 0.2, 1.0).normalize();
    let seg = medium.segment(Vec3::new(0.0, 0.0, -1.0), dir, 10.0).unwrap();
    let d = 1.0 / dir.z;
    assert!((seg.length() - d).abs() < 1e-5, "segment {} vs {d}", seg.length());
    let exact = (-(sigma_t * d) as f64).exp();
    assert!((optical_depth(&medium, &seg) - f64::from(sigma_t * d)).abs() < 1e-4);
    for (i, est) in all_estimators().into_iter().enumerate() {
        let m = mean_of(est, &medium, &seg, 200_000, 10 + i as u32);
        // The ray-marching estimators are exact here (μ − μ_min = 0): SE is 0, allow rounding.
        assert!(
            (m.mean() - exact).abs() <= Z * m.se() + 1e-5,
            "{}: {} vs exp(-σ_t d) = {exact} (SE {})",
            est.label(),
            m.mean(),
            m.se()
        );
    }
}

#[test]
fn unbiased_estimators_are_unbiased_on_the_cloud() {
    let medium = cloud(128);
    let rays = cloud_rays(&medium, 6);
    assert!(rays.len() >= 5);
    for (r, seg) in rays.iter().enumerate() {
        let exact = (-optical_depth(&medium, seg)).exp();
        for est in [
            Estimator::TrackLength,
            Estimator::RatioTracking,
            Estimator::UnbiasedRayMarching { multiplier: 1.0 },
        ] {
            let m = mean_of(est, &medium, seg, 100_000, 1000 + r as u32);
            assert!(
                (m.mean() - exact).abs() <= Z * m.se(),
                "ray {r} {}: {} vs exact {exact} (SE {})",
                est.label(),
                m.mean(),
                m.se()
            );
            if est == Estimator::TrackLength {
                // Bernoulli: std sqrt((1 − T)T); the std's SE is var_se / (2 std).
                let want = ((1.0 - exact) * exact).sqrt();
                let se = m.var_se() / (2.0 * want.max(1e-3));
                assert!(
                    (m.std() - want).abs() <= Z * se + 1e-3,
                    "ray {r} track-length std {} vs {want}",
                    m.std()
                );
            }
        }
    }
}

#[test]
fn jackknife_has_at_most_half_the_naive_bias_at_equal_mn() {
    let medium = cloud(128);
    let rays = cloud_rays(&medium, 8);
    let (mut jack_bias, mut naive_bias, mut var) = (0.0, 0.0, 0.0);
    for (r, seg) in rays.iter().enumerate() {
        let exact = (-optical_depth(&medium, seg)).exp();
        let j =
            mean_of(Estimator::Jackknife { samples: 8 }, &medium, seg, 400_000, 2000 + r as u32);
        let n = mean_of(Estimator::Naive { samples: 16 }, &medium, seg, 400_000, 3000 + r as u32);
        println!(
            "ray {r}: T {exact:.4} jackknife {:.5} ± {:.5} naive {:.5} ± {:.5}",
            j.mean() - exact,
            j.se(),
            n.mean() - exact,
            n.se()
        );
        jack_bias += (j.mean() - exact).abs();
        naive_bias += (n.mean() - exact).abs();
        var += j.se().powi(2) + 0.25 * n.se().powi(2);
    }
    // One-sided: half the naive sum minus the jackknife sum, above Z of its standard error.
    let margin = 0.5 * naive_bias - jack_bias;
    assert!(
        margin > Z * var.sqrt(),
        "Σ|bias| jackknife {jack_bias} vs naive {naive_bias}: margin {margin} ≤ {Z} × SE {}",
        var.sqrt()
    );
}

/// RMSE of `f` over `trials` runs against the exact integral.
fn rmse(f: impl Fn(&mut Pcg) -> f32, exact: f64, trials: usize, seed: u32) -> f64 {
    let mut rng = Pcg::new(seed);
    let se: f64 = (0..trials).map(|_| (f64::from(f(&mut rng)) - exact).powi(2)).sum();
    (se / trials as f64).sqrt()
}

#[test]
fn fig5_stratified_jittered_converges_close_to_one_over_n() {
    // The extinction profile along a ray through the cloud (256 voxels deep).
    let medium = cloud(256);
    let seg = medium.segment(Vec3::new(0.05, 0.1, -4.0), Vec3::Z, 100.0).unwrap();
    let t_max = seg.length();
    let mu = |t: f32| {
        let p = seg.at(seg.t0 + t.min(t_max * 0.999_999));
        medium.density.lookup(p, UVec3::ZERO, medium.density.res - UVec3::ONE)
    };
    let exact = optical_depth(&medium, &seg);
    assert!(exact > 1.0, "the ray must cross the cloud: τ = {exact}");
    let ns = [2u32, 4, 8, 16, 32, 64];
    let strat: Vec<f64> = ns
        .iter()
        .map(|&n| rmse(|r| stratified_jittered(mu, t_max, n, r), exact, 10_000, n))
        .collect();
    let iid: Vec<f64> = ns
        .iter()
        .map(|&n| rmse(|r| iid_uniform(mu, t_max, n, r), exact, 10_000, 100 + n))
        .collect();
    let x: Vec<f64> = ns.iter().map(|&n| f64::from(n)).collect();
    let (s, u) = (common::log_slope(&x, &strat), common::log_slope(&x, &iid));
    println!("RMSE slope: stratified jittered {s:.3}, i.i.d. {u:.3}; stratified {strat:?}");
    // The paper: "closer to linear convergence than to the 1/√N of uniform i.i.d. samples".
    assert!(s < -0.75, "stratified jittered slope {s}");
    assert!((u + 0.5).abs() < 0.1, "i.i.d. slope {u} (the test's own check: 1/√N)");
}
