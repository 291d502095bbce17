//! Eq. 3 and Eq. 6 for any m ≥ 2 (media::jackknife_function) and Table 1's analogue on normal
//! inputs. Margins are standard errors of the same run (4.5 of them), not tuned constants.
//!
//! Table 1's model of σ(N) is media::jackknife_table's. Every entry of the table but the two
//! that fix σ(N) is predicted and printed beside the paper's; asserted is what normal inputs
//! guarantee (Eq. 3 unbiased for every m ≥ 2; the naive m = 1 estimate's bias and std in
//! closed form) and the table's conclusion as far as normal inputs carry it (see the test).

mod common;

use common::{Moments, normal};
use media::Pcg;
use media::jackknife::jackknife_estimates;
use media::jackknife_function::{jackknife_function, jackknife_transmittance_m, mean_and_variance};
use media::jackknife_table::{T, TABLE_1, sigma_of, trial};

const Z: f64 = 4.5;
const TRIALS: usize = 1_000_000;

/// (estimate, its Moments) of `TRIALS` estimates from m normal optical depths N(τ, σ(N)²);
/// m = 1: the naive exp(−X).
fn row(m: usize, n: u32, seed: u32) -> Moments {
    let mut rng = Pcg::new(seed);
    let mut k = Moments::default();
    let mut x = [0.0; 8];
    for _ in 0..TRIALS {
        k.add(trial(m, n, &mut rng, &mut x));
    }
    k
}

#[test]
fn eq3_reduces_to_eq4_and_to_bessel_j0_and_eq6_to_the_complex_form() {
    // m = 2: cos(S) exp(−X̄), S = |X0 − X1|/2.
    for (x0, x1) in [(1.0f64, 2.5), (0.3, 0.31), (4.0, 0.5)] {
        let want = (0.5 * (x0 - x1)).abs().cos() * (-0.5 * (x0 + x1)).exp();
        let got = jackknife_transmittance_m(&[x0, x1]);
        assert!((got - want).abs() <= 1e-14, "m = 2: {got} vs Eq. 4 {want}");
    }
    // m = 3: Γ(1) (2/S)^0 J_0(S) exp(−X̄); J_0(1) = 0.7651976865579666 (Abramowitz & Stegun).
    // X = (a − d, a, a + d) has S² = 2d²/3; S = 1 at d = sqrt(3/2).
    let d = 1.5f64.sqrt();
    let got = jackknife_transmittance_m(&[2.0 - d, 2.0, 2.0 + d]);
    let want = 0.765_197_686_557_966_6 * (-2.0f64).exp();
    assert!((got - want).abs() <= 1e-14, "m = 3: {got} vs J_0(1) e^-2 {want}");
    // m = 4: Γ(3/2) (2/S)^{1/2} J_{1/2}(S) = sin(S)/S.
    let x = [0.2, 1.1, 0.7, 2.0];
    let (mean, s2) = mean_and_variance(&x);
    let s = s2.sqrt();
    let want = s.sin() / s * (-mean).exp();
    let got = jackknife_transmittance_m(&x);
    assert!((got - want).abs() <= 1e-14, "m = 4: {got} vs sin(S)/S e^-X̄ {want}");
    // Eq. 6 at m = 2 is Re g(X̄ + iS) (Sec. 5.1): g = exp(−kτ) gives e^{−kX̄} cos(kS).
    for k in [0.5f64, 2.0, 3.0] {
        let (mean, s2) = mean_and_variance(&[0.4, 1.9]);
        let got = jackknife_function(2, mean, s2, |j, v| k.powi(2 * j as i32) * (-k * v).exp());
        let want = (-k * mean).exp() * (k * s2.sqrt()).cos();
        assert!((got - want).abs() <= 1e-14, "Eq. 6, k = {k}: {got} vs {want}");
    }
    // The f32 twin of the shaders against the f64 series.
    for x in [[0.5f32, 1.5, 1.0, 0.2, 2.4], [3.0, 2.0, 2.5, 2.7, 1.1], [0.1, 0.1, 0.1, 0.1, 0.1]] {
        let want = jackknife_transmittance_m(&x.map(f64::from));
        let got = f64::from(jackknife_estimates(&x));
        assert!((got - want).abs() <= 1e-6 * want.abs().max(1e-3), "f32 twin {got} vs {want}");
    }
}

#[test]
fn eq6_is_unbiased_for_a_polynomial_and_eq3_for_every_m_on_normal_inputs() {
    // g(τ) = τ²: G = X̄² − S²/(m − 1) (E X̄² = τ² + σ²/m, E S² = σ² (m − 1)/m).
    let (tau, sigma) = (1.3f64, 0.8f64);
    for (m, seed) in [(2usize, 11u32), (3, 12), (5, 13), (9, 14)] {
        let mut rng = Pcg::new(seed);
        let (mut g, mut naive) = (Moments::default(), Moments::default());
        let mut x = vec![0.0; m];
        for _ in 0..TRIALS {
            for v in x.iter_mut() {
                *v = tau + sigma * normal(&mut rng);
            }
            let (mean, s2) = mean_and_variance(&x);
            g.add(jackknife_function(m, mean, s2, |j, v| match j {
                0 => v * v,
                1 => 2.0,
                _ => 0.0,
            }));
            naive.add(mean * mean);
        }
        let want = tau * tau;
        println!(
            "g = τ², m = {m}: Eq. 6 {:.5} ± {:.5}, naive X̄² {:.5}, τ² {want:.5}",
            g.mean(),
            g.se(),
            naive.mean()
        );
        assert!((g.mean() - want).abs() <= Z * g.se(), "Eq. 6, m = {m}: {} vs {want}", g.mean());
        // The naive g(X̄) is off by σ²/m, many standard errors here.
        assert!((naive.mean() - want - sigma * sigma / m as f64).abs() <= Z * naive.se());
    }
}

#[test]
fn table_1_on_normal_inputs() {
    let rows: Vec<Moments> =
        TABLE_1.iter().enumerate().map(|(i, &(m, n, ..))| row(m, n, 100 + i as u32)).collect();
    println!(
        "m   N   σ(N)    mean     bias ± SE            std ± SE          | paper: mean bias std"
    );
    for (r, &(m, n, mean, bias, std)) in rows.iter().zip(&TABLE_1) {
        // SE of the std: SE of the variance / (2 std).
        println!(
            "{m}  {n:2}  {:.4}  {:.5}  {:+.5} ± {:.5}  {:.4} ± {:.4}  | {mean:.5} {bias:.5} {std:.4}",
            sigma_of(n),
            r.mean(),
            r.mean() - T,
            r.se(),
            r.std(),
            r.var_se() / (2.0 * r.std()),
        );
    }
    // Eq. 3 is unbiased for every m ≥ 2 on normal inputs (the paper's m = 2 row: 0.00000).
    for (r, &(m, ..)) in rows.iter().zip(&TABLE_1).take(5) {
        assert!(
            (r.mean() - T).abs() <= Z * r.se(),
            "m = {m}: bias {} (SE {})",
            r.mean() - T,
            r.se()
        );
    }
    // The naive m = 1 row in closed form (Appendix A.1): bias T (e^{σ²/2} − 1), the paper's
    // 0.00386 by construction of σ(24); std T e^{σ²/2} sqrt(e^{σ²} − 1).
    let (naive, s) = (&rows[5], sigma_of(24));
    let bias = T * ((0.5 * s * s).exp() - 1.0);
    let std = T * (0.5 * s * s).exp() * ((s * s).exp() - 1.0).sqrt();
    assert!((naive.mean() - T - bias).abs() <= Z * naive.se(), "m = 1 bias {}", naive.mean() - T);
    let std_se = naive.var_se() / (2.0 * naive.std());
    assert!((naive.std() - std).abs() <= Z * std_se, "m = 1 std {} vs {std}", naive.std());
    // The m = 2 row's std is the paper's by construction of σ(12).
    let jk_se = rows[0].var_se() / (2.0 * rows[0].std());
    assert!((rows[0].std() - 0.0405).abs() <= Z * jk_se + 0.00005, "m = 2 std {}", rows[0].std());
    // The table's conclusion: m = 2 has the lowest std of the unbiased rows, and the naive m = 1
    // estimate, slightly less noisy, carries a bias above every m ≥ 2 row's by many SE.
    for (r, &(m, ..)) in rows.iter().zip(&TABLE_1).skip(1).take(4) {
        let se = (r.var_se() / (2.0 * r.std())).hypot(jk_se);
        assert!(r.std() - rows[0].std() > Z * se, "m = {m}: std {} not above m = 2's", r.std());
    }
    assert!(naive.std() < rows[0].std());
    assert!(naive.mean() - T > Z * naive.se() + (rows[0].mean() - T).abs() + Z * rows[0].se());
}
