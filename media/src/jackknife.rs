//! The jackknife transmittance estimate: Eq. 4, the UMVU estimate of exp(−τ) from m = 2 i.i.d.
//! normal optical-depth estimates, K = cos(|X0 − X1|/2) · exp(−(X0 + X1)/2), unbiased for normal
//! inputs with V(K) = (exp(σ²) − 1)/2 · exp(−2τ); and Eq. 3 for any m ≥ 2 (f32, the WGSL
//! twin's arithmetic; the f64 reference is `jackknife_function`). Not clamped: it may be
//! negative.

use crate::medium::{Estimate, Medium, Segment};
use crate::optical_depth::{Importance, Jitter, MAX_ESTIMATES, SampleCount, estimate, prepare};
use crate::rng::Pcg;

pub fn jackknife(x0: f32, x1: f32) -> f32 {
    (0.5 * (x0 - x1).abs()).cos() * (-0.5 * (x0 + x1)).exp()
}

/// Terms of the f32 series of Eq. 3 at most (media_jackknife.wgsl's bound).
pub const SERIES_TERMS: u32 = 64;

/// Eq. 3 from m = `x.len()` ≥ 2 estimates: Eq. 4 for m = 2, else exp(−X̄) ₀F₁(; (m−1)/2; −S²/4)
/// by its series in f32, as media_jackknife.wgsl (accurate to ~1e-6 relative while S ≲ 6; the
/// terms then grow to ~e^S before they fall).
pub fn jackknife_estimates(x: &[f32]) -> f32 {
    let m = x.len();
    if m == 2 {
        return jackknife(x[0], x[1]);
    }
    let mean = x.iter().sum::<f32>() / m as f32;
    let s2 = x.iter().map(|v| (v - mean) * (v - mean)).sum::<f32>() / m as f32;
    let a = 0.5 * (m as f32 - 1.0);
    let z = -0.25 * s2;
    let (mut term, mut sum) = (1.0f32, 1.0f32);
    for j in 1..SERIES_TERMS {
        let jf = j as f32;
        term *= z / (jf * (a + jf - 1.0));
        sum += term;
        if jf * (a + jf - 1.0) > -z && term.abs() <= 1e-8 * sum.abs() {
            break;
        }
    }
    sum * (-mean).exp()
}

/// How one jackknife transmittance estimate is taken: m estimates (2 in the paper) of N samples
/// each (fixed, the paper's choice, or tied to the importance along the ray, Fig. 8d).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct JackknifeSettings {
    pub estimates: usize,
    pub samples: SampleCount,
}

/// Two estimates of N = `samples` samples each, variance-aware importance, stratified jitter.
pub fn jackknife_transmittance(
    medium: &Medium,
    seg: &Segment,
    samples: u32,
    rng: &mut Pcg,
) -> Estimate {
    let settings = JackknifeSettings { estimates: 2, samples: SampleCount::Fixed(samples) };
    jackknife_transmittance_with(medium, seg, &settings, rng)
}

/// Eq. 3 from `settings.estimates` estimates (variance-aware importance, stratified jitter): the
/// CPU twin of the volumetric path tracer's jackknife shadow rays.
pub fn jackknife_transmittance_with(
    medium: &Medium,
    seg: &Segment,
    settings: &JackknifeSettings,
    rng: &mut Pcg,
) -> Estimate {
    let m = settings.estimates;
    assert!((2..=MAX_ESTIMATES).contains(&m), "m = {m}; Eq. 3 needs 2 to {MAX_ESTIMATES}");
    let prep = prepare(medium, seg, Importance::VarianceAware);
    let mut x = [0.0; MAX_ESTIMATES];
    let n = settings.samples.count(prep.total);
    let lookups = estimate(
        medium,
        seg,
        &prep,
        m,
        n,
        Importance::VarianceAware,
        Jitter::Stratified,
        rng,
        &mut x,
    );
    Estimate { value: jackknife_estimates(&x[..m]), lookups }
}
