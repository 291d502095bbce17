//! SPVG (eqs. 4.3-4.12) and the control variates (eqs. 2.18, 6.16, 6.21) on synthetic streams:
//! sss::spvg and sss::control_variates.

use render::scene::SplitMix64;
use sss::control_variates::{EmCovariance, optimal_coefficient};
use sss::screen_pass::step;
use sss::spvg::{self, SpvgHistory, SpvgSettings};
use sss::{PixelHistory, SssFrame, SssPassSettings};

/// Standard normal by Box-Muller.
fn normal(rng: &mut SplitMix64) -> f64 {
    let u1 = (rng.next_f32() as f64).max(1e-12);
    let u2 = rng.next_f32() as f64;
    (-2.0 * u1.ln()).sqrt() * (2.0 * std::f64::consts::PI * u2).cos()
}

/// One pixel under SPVG for `variance.len()` frames: each frame's value is the mean of n
/// samples of per-sample variance v_t around 0.5. Returns the counts.
fn run_pixel(variance: &[f64], s: &SpvgSettings, seed: u64) -> Vec<u32> {
    let mut rng = SplitMix64::new(seed);
    let mut h = SpvgHistory::default();
    variance
        .iter()
        .map(|&v| {
            let st = spvg::state(&h, s);
            let n = spvg::sample_count(&st, s);
            let value = 0.5 + normal(&mut rng) * (v / n as f64).sqrt();
            h = spvg::update(&st, s, value as f32, n);
            n
        })
        .collect()
}

fn mean(v: &[u32]) -> f64 {
    v.iter().map(|&x| x as f64).sum::<f64>() / v.len() as f64
}

#[test]
fn counts_stay_clamped_rise_after_a_variance_step_and_fall_back() {
    let s = SpvgSettings::default();
    // Per-sample variance 4e-4 needs 4 samples for σ0² = 1e-4 (clamped to 8); 4e-3 needs 40.
    let schedule: Vec<f64> =
        (0..300).map(|t| if (100..200).contains(&t) { 4e-3 } else { 4e-4 }).collect();
    for seed in 1..=3 {
        let counts = run_pixel(&schedule, &s, seed);
        assert!(counts.iter().all(|&n| (8..=64).contains(&n)), "seed {seed}: {counts:?}");
        // The first frame is a cold start: no history, n_min (Fig. 4.3, no initial overshoot).
        assert_eq!(counts[0], 8);
        let (before, during, after) =
            (mean(&counts[70..100]), mean(&counts[150..200]), mean(&counts[270..300]));
        eprintln!(
            "seed {seed}: mean count before {before:.1}, during {during:.1}, after {after:.1}"
        );
        assert!(before < 10.0, "seed {seed}: {before}");
        // n ≈ v/σ0² = 40 at equilibrium: well above the floor.
        assert!(during > 25.0 && during > 2.5 * before, "seed {seed}: {during} vs {before}");
        assert!(after < 10.0, "seed {seed}: {after}");
        // The rise starts within a few frames of the step.
        assert!(mean(&counts[100..115]) > before + 5.0, "seed {seed}: {:?}", &counts[95..115]);
    }
}

#[test]
fn disocclusion_resets_the_history() {
    let s = SpvgSettings::default();
    let busy = SpvgHistory { mu: 0.7, sigma2: 50.0 * s.sigma0_sq, nbar: 60.0, valid: true };
    let st = spvg::state(&busy, &s);
    assert_eq!(spvg::sample_count(&st, &s), 64);
    // C_s = 0 (eq. 4.11): α = 1, σ̂² = σ0² (eq. 4.12), n from β_min.
    let reset = spvg::state(&SpvgHistory { valid: false, ..busy }, &s);
    assert_eq!((reset.alpha, reset.sigma2, reset.valid), (1.0, s.sigma0_sq, false));
    assert_eq!(spvg::sample_count(&reset, &s), 8);
    let after = spvg::update(&reset, &s, 0.3, 8);
    assert_eq!(after, SpvgHistory { mu: 0.3, sigma2: s.sigma0_sq, nbar: 8.0, valid: true });
    // The next frame keeps the reset count: σ² = σ0² gives E[n̄] = n̄ and Δ = 0.
    assert_eq!(spvg::sample_count(&spvg::state(&after, &s), &s), 8);

    // Through the pass: a pixel that leaves the SSS mask for a frame comes back at n_min.
    let mut frame = SssFrame {
        width: 4,
        height: 1,
        irradiance: vec![[1.0, 1.0, 1.0, 1.0]; 4],
        d_px: [0.5; 3],
        focal_px: 0.0,
        motion: Vec::new(),
    };
    let settings = SssPassSettings::default();
    let hot = PixelHistory { spvg: busy, ..Default::default() };
    let (r, h) = step(&frame, &settings, 0, &[hot; 4]);
    assert!(r.iter().all(|p| p.count == 64));
    frame.irradiance[2][3] = 0.0;
    let (r, h) = step(&frame, &settings, 1, &h);
    assert_eq!(r[2].count, 0);
    frame.irradiance[2][3] = 1.0;
    let (r, _) = step(&frame, &settings, 2, &h);
    assert_eq!(r[2].count, 8, "{r:?}");
    assert!(r[1].count > 8);
}

#[test]
fn bad_settings_are_refused() {
    for (s, word) in [
        (SpvgSettings { alpha0: 0.0, ..Default::default() }, "alpha0"),
        (SpvgSettings { kappa: 1.5, ..Default::default() }, "kappa"),
        (SpvgSettings { sigma0_sq: 0.0, ..Default::default() }, "sigma0_sq"),
        (SpvgSettings { n_min: 65, ..Default::default() }, "n_min"),
    ] {
        assert!(s.validate().unwrap_err().contains(word), "{s:?}");
    }
    assert!(SpvgSettings::default().validate().is_ok());
}

/// Eq. 6.16 is the exponentially weighted covariance E_t((X − μ_t)(Y − ν_t)) of eq. 6.20 with
/// weights (1 − α)^t on the first observation and α(1 − α)^{t−i} on the others.
#[test]
fn emc_is_the_exponentially_weighted_covariance() {
    let alpha = 0.1f64;
    let mut rng = SplitMix64::new(11);
    let xs: Vec<f64> = (0..150).map(|_| rng.range(0.0, 2.0) as f64).collect();
    let ys: Vec<f64> = xs.iter().map(|x| 0.5 * x + rng.range(-0.5, 0.5) as f64).collect();
    let mut emc = EmCovariance::start(xs[0] as f32, ys[0] as f32);
    for t in 1..xs.len() {
        emc = emc.update(alpha as f32, xs[t] as f32, ys[t] as f32);
        let w: Vec<f64> = (0..=t)
            .map(|i| {
                if i == 0 {
                    (1.0 - alpha).powi(t as i32)
                } else {
                    alpha * (1.0 - alpha).powi((t - i) as i32)
                }
            })
            .collect();
        let mx: f64 = (0..=t).map(|i| w[i] * xs[i]).sum();
        let my: f64 = (0..=t).map(|i| w[i] * ys[i]).sum();
        let cov: f64 = (0..=t).map(|i| w[i] * (xs[i] - mx) * (ys[i] - my)).sum();
        let var: f64 = (0..=t).map(|i| w[i] * (ys[i] - my) * (ys[i] - my)).sum();
        assert!((emc.cov_fg as f64 - cov).abs() < 1e-5, "t {t}: {} vs {cov}", emc.cov_fg);
        assert!((emc.var_g as f64 - var).abs() < 1e-5, "t {t}: {} vs {var}", emc.var_g);
        assert!((emc.mean_f as f64 - mx).abs() < 1e-5 && (emc.mean_g as f64 - my).abs() < 1e-5);
    }
}

/// f = b g + c + e on independent g, e: the coefficient (eq. 6.21, a_cv = 0.005, ε_a = 1e-6)
/// converges to Cov(f, g)/Var(g) = b. The EMC's window holds about (2 − α)/α ≈ 400 frames:
/// the estimate's standard deviation is σ_e/(σ_g √400) = 0.1/(0.3 · 20) ≈ 0.017; bound 4σ.
#[test]
fn cv_coefficient_converges_to_cov_over_var() {
    let (alpha, sigma_g, sigma_e) = (0.005f32, 0.3, 0.1);
    let tolerance = 4.0 * sigma_e / (sigma_g * ((2.0 - alpha as f64) / alpha as f64).sqrt());
    for b in [0.5, 2.0] {
        for seed in 1..=3u64 {
            let mut rng = SplitMix64::new(100 * seed + (b * 10.0) as u64);
            let mut emc = EmCovariance::start(0.0, 1.0);
            let mut last = (0.0, 0.0);
            for _ in 0..6000 {
                let g = 1.0 + sigma_g * normal(&mut rng);
                let f = b * g + 0.2 + sigma_e * normal(&mut rng);
                emc = emc.update(alpha, f as f32, g as f32);
                last = (f, g);
            }
            let a = emc.coefficient(1e-6, 1000.0, last.0 as f32, last.1 as f32) as f64;
            assert!((a - b).abs() < tolerance, "b {b} seed {seed}: a {a}, tolerance {tolerance}");
        }
    }
}

#[test]
fn cv_coefficient_bounds() {
    // No covariance at all (hard shadows): ε_a makes it major part separation, a = 1.
    assert_eq!(EmCovariance::default().coefficient(1e-6, 1000.0, 0.5, 0.5), 1.0);
    // Negative covariance clamps to 0; a huge ratio to a0 + f̄/ḡ (D of Sec. 6.5.4).
    let neg = EmCovariance { cov_fg: -0.1, var_g: 0.01, ..Default::default() };
    assert_eq!(neg.coefficient(1e-6, 1000.0, 0.5, 0.5), 0.0);
    let huge = EmCovariance { cov_fg: 1e3, var_g: 1e-9, ..Default::default() };
    assert_eq!(huge.coefficient(1e-6, 2.0, 0.6, 0.3), 4.0);
}

/// The optimum below eq. 2.18 is Cov/Var(G), not Cov/Var(F) as printed: on samples with
/// Var(F) ≠ Var(G), the empirical Var(F − aG) is smallest at Cov/Var(G), and the printed
/// coefficient leaves far more variance.
#[test]
fn eq_2_18_optimum_has_var_g_in_the_denominator() {
    let mut rng = SplitMix64::new(5);
    let n = 20_000;
    let g: Vec<f64> = (0..n).map(|_| 0.3 * normal(&mut rng)).collect();
    let f: Vec<f64> = g.iter().map(|g| 2.0 * g + 0.1 * normal(&mut rng)).collect();
    let m = |v: &[f64]| v.iter().sum::<f64>() / v.len() as f64;
    let (mf, mg) = (m(&f), m(&g));
    let cov = f.iter().zip(&g).map(|(f, g)| (f - mf) * (g - mg)).sum::<f64>() / n as f64;
    let var_f = f.iter().map(|f| (f - mf).powi(2)).sum::<f64>() / n as f64;
    let var_g = g.iter().map(|g| (g - mg).powi(2)).sum::<f64>() / n as f64;
    let residual = |a: f64| {
        let r: Vec<f64> = f.iter().zip(&g).map(|(f, g)| f - a * g).collect();
        let mr = m(&r);
        r.iter().map(|r| (r - mr).powi(2)).sum::<f64>() / n as f64
    };
    let right = optimal_coefficient(cov, var_g);
    let printed = cov / var_f;
    for step in [-0.05, -0.005, 0.005, 0.05] {
        assert!(residual(right) < residual(right + step), "a {right} vs {}", right + step);
    }
    assert!((right - 2.0).abs() < 0.02, "{right}");
    assert!(
        residual(printed) > 10.0 * residual(right),
        "printed a {printed}: {} vs {}",
        residual(printed),
        residual(right)
    );
    // Eq. 2.19 holds at the right optimum: Var = (1 − Corr²) Var(F).
    let corr2 = cov * cov / (var_f * var_g);
    assert!((residual(right) - (1.0 - corr2) * var_f).abs() < 1e-9);
}
