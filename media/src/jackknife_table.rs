//! Table 1 of the paper (bias and standard deviation of Eq. 3 against m and N at mN = 24) on
//! normal optical-depth inputs: the table, the model of σ(N) it implies and one trial of each
//! row. Shared by the media tests and `flicker reproduce`'s claims.
//!
//! The paper measures transmittance along Fig. 4a's profile (10^8 trials) and does not list
//! σ(N), the standard deviation of one optical-depth estimate of N stratified samples. Two of
//! its numbers fix it: the m = 2 row's std (V(K) = (e^{σ²} − 1) T²/2, Sec. 3.3) gives σ(12),
//! the m = 1 row's bias (T (e^{σ²/2} − 1), Appendix A.1) gives σ(24), and σ(N) = σ(12)
//! (12/N)^α between and beyond them (α from the two). T = 0.13411 is the m = 2 row's mean (its
//! bias is 0.00000). Every other entry is then a prediction.

use crate::jackknife_function::jackknife_transmittance_m;
use crate::rng::{Pcg, normal_f64};

/// Table 1: (m, N, mean, bias, std); m = 1 is the naive exp(−X) of all mN samples.
pub const TABLE_1: [(usize, u32, f64, f64, f64); 6] = [
    (2, 12, 0.13411, 0.00000, 0.0405),
    (3, 8, 0.13425, 0.00014, 0.0440),
    (4, 6, 0.13421, 0.00010, 0.0528),
    (6, 4, 0.13433, 0.00022, 0.0490),
    (8, 3, 0.13485, 0.00074, 0.0694),
    (1, 24, 0.13797, 0.00386, 0.0331),
];

/// The true transmittance of Table 1 (its m = 2 row's mean).
pub const T: f64 = 0.13411;

/// σ(N) of the model above.
pub fn sigma_of(n: u32) -> f64 {
    let s12 = (1.0 + 2.0 * (0.0405 / T).powi(2)).ln().sqrt();
    let s24 = (2.0 * (1.0 + 0.00386 / T).ln()).sqrt();
    let alpha = (s12 / s24).log2();
    s12 * (12.0 / f64::from(n)).powf(alpha)
}

/// One trial of row (m, N): m normal optical depths N(τ, σ(N)²), τ = −ln T, and Eq. 3 of them
/// (m = 1: the naive exp(−X)). `x` holds at least m values (scratch).
pub fn trial(m: usize, n: u32, rng: &mut Pcg, x: &mut [f64]) -> f64 {
    let (tau, sigma) = (-T.ln(), sigma_of(n));
    let x = &mut x[..m];
    for v in x.iter_mut() {
        *v = tau + sigma * normal_f64(rng);
    }
    if m == 1 { (-x[0]).exp() } else { jackknife_transmittance_m(x) }
}
