//! The jackknife transmittance estimate (Eq. 4): the UMVU estimate of exp(−τ) from m = 2 i.i.d.
//! normal optical-depth estimates, K = cos(|X0 − X1|/2) · exp(−(X0 + X1)/2). Unbiased for
//! normal inputs with V(K) = (exp(σ²) − 1)/2 · exp(−2τ). Not clamped: it may be negative.

use crate::medium::{Estimate, Medium, Segment};
use crate::optical_depth::{Importance, Jitter, MAX_ESTIMATES, estimate, prepare};
use crate::rng::Pcg;

pub fn jackknife(x0: f32, x1: f32) -> f32 {
    (0.5 * (x0 - x1).abs()).cos() * (-0.5 * (x0 + x1)).exp()
}

/// Two estimates of N = `samples` samples each, variance-aware importance, stratified jitter.
pub fn jackknife_transmittance(
    medium: &Medium,
    seg: &Segment,
    samples: u32,
    rng: &mut Pcg,
) -> Estimate {
    let prep = prepare(medium, seg, Importance::VarianceAware);
    let mut x = [0.0; MAX_ESTIMATES];
    let lookups = estimate(
        medium,
        seg,
        &prep,
        2,
        samples,
        Importance::VarianceAware,
        Jitter::Stratified,
        rng,
        &mut x,
    );
    Estimate { value: jackknife(x[0], x[1]), lookups }
}
