//! Inverses of Burley's radial cdf (thesis Sec. 5.1.1): a numeric one (bisection + Newton, f64,
//! the reference), Golubev's analytic one (eq. 5.4/5.5) and the thesis's fast approximation
//! g(ξ) = d((2 − c)ξ − 2) log(1 − ξ), c = 2.5715 (eq. 5.6).

use super::profile::{cdf, radial_pdf};

/// The damping constant of eq. 5.6 (least-squares fit of cdf(g(ξ)) against ξ in the thesis).
pub const FAST_INVERSE_C: f64 = 2.5715;

/// r with cdf(r) = u, to f64 precision: bracket, bisect, then polish with Newton.
pub fn numeric_inverse(u: f64, d: f64) -> f64 {
    assert!((0.0..1.0).contains(&u), "cdf value {u} outside [0, 1)");
    let (mut lo, mut hi) = (0.0, d);
    while cdf(hi, d) < u {
        hi *= 2.0;
    }
    for _ in 0..200 {
        let mid = 0.5 * (lo + hi);
        if cdf(mid, d) < u {
            lo = mid
        } else {
            hi = mid
        }
        if hi - lo <= 1e-15 * hi.max(1e-300) {
            break;
        }
    }
    let mut r = 0.5 * (lo + hi);
    for _ in 0..3 {
        let step = (cdf(r, d) - u) / radial_pdf(r, d);
        r = (r - step).max(0.0);
    }
    r
}

/// Golubev's analytic inverse (eq. 5.4/5.5). As printed it takes ξ = 1 − cdf (the tail mass),
/// not the cdf value: ξ → 0 gives r → ∞. This takes the cdf value u and passes 1 − u.
pub fn analytic_inverse(u: f64, d: f64) -> f64 {
    let xi = 1.0 - u;
    let g = 1.0 + 4.0 * xi * (2.0 * xi + (1.0 + 4.0 * xi * xi).sqrt());
    3.0 * d * ((1.0 + g.powf(-1.0 / 3.0) + g.powf(1.0 / 3.0)) / (4.0 * xi)).ln()
}

/// g(ξ) = d((2 − c)ξ − 2) log(1 − ξ), eq. 5.6: an approximate inverse, cheaper than eq. 5.4.
pub fn fast_inverse(u: f64, d: f64) -> f64 {
    d * ((2.0 - FAST_INVERSE_C) * u - 2.0) * (1.0 - u).ln()
}
