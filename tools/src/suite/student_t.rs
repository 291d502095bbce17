//! Student's t distribution: its CDF (statrs) and quantile, for Welch's test, the paired gates
//! and confidence intervals. Degrees of freedom may be fractional, as Welch's are.

use statrs::distribution::{ContinuousCDF, StudentsT};

/// The standard t distribution with `df` degrees of freedom; `None` unless df > 0.
fn standard(df: f64) -> Option<StudentsT> {
    StudentsT::new(0.0, 1.0, df).ok()
}

/// P(T <= t) for Student's t with `df` degrees of freedom (NaN for a NaN t or df <= 0).
pub fn cdf(t: f64, df: f64) -> f64 {
    if t.is_nan() {
        return f64::NAN;
    }
    if t.is_infinite() {
        return if t > 0.0 { 1.0 } else { 0.0 };
    }
    standard(df).map_or(f64::NAN, |d| d.cdf(t))
}

/// The t with P(T <= t) = p, by bisection on [`cdf`] (monotone; 200 halvings reach f64
/// precision). Not statrs's `inverse_cdf`: through the inverse incomplete beta function it drifts
/// as df grows (at df = 10^7 it gives 0.700 for p = 0.8, where the normal's 0.8416 is right).
pub fn quantile(p: f64, df: f64) -> f64 {
    assert!(p > 0.0 && p < 1.0 && df > 0.0, "quantile({p}, {df}): expected 0 < p < 1 and df > 0");
    let (mut lo, mut hi) = (-1.0, 1.0);
    while cdf(lo, df) > p {
        lo *= 2.0;
    }
    while cdf(hi, df) < p {
        hi *= 2.0;
    }
    for _ in 0..200 {
        let mid = 0.5 * (lo + hi);
        if cdf(mid, df) < p { lo = mid } else { hi = mid }
    }
    0.5 * (lo + hi)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn quantile_holds_for_large_df() {
        // The normal's quantiles (df -> infinity): 0.841621, 1.644854.
        assert!((quantile(0.8, 1e7) - 0.841_621).abs() < 1e-5, "{}", quantile(0.8, 1e7));
        assert!((quantile(0.95, 1e6) - 1.644_854).abs() < 1e-5, "{}", quantile(0.95, 1e6));
    }

    // Quantiles from the standard t table (e.g. NIST/SEMATECH e-Handbook, table 1.3.6.7.2).
    #[test]
    fn quantiles_match_the_t_table() {
        for (p, df, t) in [
            (0.95, 1.0, 6.314),
            (0.95, 2.0, 2.920),
            (0.95, 4.0, 2.132),
            (0.95, 10.0, 1.812),
            (0.975, 5.0, 2.571),
            (0.99, 20.0, 2.528),
            (0.95, 100.0, 1.660),
        ] {
            let q = quantile(p, df);
            assert!((q - t).abs() < 5e-4, "t quantile p={p} df={df}: {q}, table {t}");
        }
    }

    // Six-digit quantiles (NIST/SEMATECH e-Handbook 1.3.6.7.2; R's qt gives the same digits).
    #[test]
    fn quantiles_match_published_six_digit_values() {
        for (p, df, t) in [
            (0.95, 1.0, 6.313752),
            (0.95, 2.0, 2.919986),
            (0.975, 10.0, 2.228139),
            (0.99, 5.0, 3.364930),
            (0.995, 30.0, 2.749996),
        ] {
            let q = quantile(p, df);
            assert!((q - t).abs() < 1e-6 * t, "t quantile p={p} df={df}: {q}, published {t}");
            assert!((cdf(t, df) - p).abs() < 1e-6, "cdf({t}, {df}) = {}, expected {p}", cdf(t, df));
        }
    }

    #[test]
    fn cdf_is_symmetric_and_tends_to_the_normal() {
        assert!((cdf(0.0, 3.0) - 0.5).abs() < 1e-12);
        assert!((cdf(1.3, 7.5) + cdf(-1.3, 7.5) - 1.0).abs() < 1e-12);
        // Φ(1.644854) = 0.95
        assert!((cdf(1.644_854, 1e7) - 0.95).abs() < 1e-5);
        // df = 1 is the Cauchy distribution: P(T <= 1) = 3/4.
        assert!((cdf(1.0, 1.0) - 0.75).abs() < 1e-12);
    }

    // The CDF rests on ln Γ through the incomplete beta function.
    #[test]
    fn ln_gamma_of_integers_is_ln_factorial() {
        use statrs::function::gamma::ln_gamma;
        assert!((ln_gamma(1.0)).abs() < 1e-12);
        assert!((ln_gamma(5.0) - 24f64.ln()).abs() < 1e-12);
        assert!((ln_gamma(0.5) - std::f64::consts::PI.sqrt().ln()).abs() < 1e-12);
    }
}
