//! Transmittance as exp(−X) of one optical-depth estimate X (biased: overestimates by Jensen's
//! inequality, by (exp(σ²/2) − 1)·T for normal X).
//! - `naive`: the paper's own optical-depth estimator (variance-aware importance, control
//!   variate, stratified) with all mN samples in one estimate (Table 1's m = 1 row).
//! - `biased_ray_marching`: Kettunen et al. 2021: mean importance, uniform jitter, their
//!   sample count from the control optical depth, times `multiplier` (2 in the paper's Fig. 8).

use crate::medium::{Estimate, Medium, Segment};
use crate::optical_depth::{
    Importance, Jitter, MAX_ESTIMATES, estimate, kettunen_sample_count, prepare,
};
use crate::rng::Pcg;

pub fn naive(medium: &Medium, seg: &Segment, samples: u32, rng: &mut Pcg) -> Estimate {
    let prep = prepare(medium, seg, Importance::VarianceAware);
    let mut x = [0.0; MAX_ESTIMATES];
    let lookups = estimate(
        medium,
        seg,
        &prep,
        1,
        samples,
        Importance::VarianceAware,
        Jitter::Stratified,
        rng,
        &mut x,
    );
    Estimate { value: (-x[0]).exp(), lookups }
}

pub fn biased_ray_marching(
    medium: &Medium,
    seg: &Segment,
    multiplier: f32,
    rng: &mut Pcg,
) -> Estimate {
    let prep = prepare(medium, seg, Importance::Mean);
    let samples = kettunen_sample_count(prep.total, multiplier);
    let mut x = [0.0; MAX_ESTIMATES];
    let lookups =
        estimate(medium, seg, &prep, 1, samples, Importance::Mean, Jitter::Uniform, rng, &mut x);
    Estimate { value: (-x[0]).exp(), lookups }
}
