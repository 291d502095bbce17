//! Unbiased ray marching (Kettunen et al. 2021, as the paper configures it): the power series
//! exp(−τ) = exp(−X_i) Σ_j (X_i − τ)^j / j! around each of d + 1 i.i.d. optical-depth
//! estimates X_i in turn, (X_i − τ)^j estimated by the elementary means (U-statistics) of the
//! other d offsets X_i − X_l, the degree d drawn by aggressive Bhanot–Kennedy roulette
//! (order 0 with probability p_Z = 0.9, else at least order 2, then c_k = min(1, 2/k)),
//! capped at 8 as in the paper (so unbiased up to the truncation beyond degree 8). The
//! estimates use mean importance, uniform jitter and Kettunen et al.'s sample count; no
//! endpoint matching (as in the paper).

use crate::medium::{Estimate, Medium, Segment};
use crate::optical_depth::{
    Importance, Jitter, MAX_ESTIMATES, estimate, kettunen_sample_count, prepare,
};
use crate::rng::Pcg;

pub const MAX_DEGREE: usize = MAX_ESTIMATES - 1;
const P_Z: f32 = 0.9;
const MIN_EXPANSION: usize = 2;
const BK_C: f32 = 2.0;

/// The roulette: the degree d and P(degree ≥ k) for k ≤ d. Consumes one random number.
pub fn power_series_degree(rng: &mut Pcg) -> (usize, [f32; MAX_DEGREE + 1]) {
    let mut prob = [1.0; MAX_DEGREE + 1];
    let u = rng.next_f32();
    let mut p = 1.0 - P_Z;
    if p <= u {
        return (0, prob);
    }
    for pk in prob.iter_mut().take(MIN_EXPANSION + 1).skip(1) {
        *pk = p;
    }
    for k in MIN_EXPANSION + 1..=MAX_DEGREE {
        p *= (BK_C / k as f32).min(1.0);
        if p <= u {
            return (k - 1, prob);
        }
        prob[k] = p;
    }
    (MAX_DEGREE, prob)
}

/// Elementary means e_k(x) / C(n, k) of the first `n` inputs, k = 0..=MAX_DEGREE (Kettunen et
/// al.'s recursion; entries past n stay 0).
pub fn elementary_means(x: &[f32; MAX_DEGREE], n: usize) -> [f32; MAX_DEGREE + 1] {
    let mut m = [0.0; MAX_DEGREE + 1];
    m[0] = 1.0;
    for (i, &xi) in x.iter().enumerate().take(n) {
        for k in (1..=i + 1).rev() {
            m[k] += k as f32 / (i + 1) as f32 * (m[k - 1] * xi - m[k]);
        }
    }
    m
}

/// The estimate from d + 1 optical depths `x[..=degree]` and the roulette's probabilities.
pub fn power_series(x: &[f32; MAX_ESTIMATES], degree: usize, prob: &[f32; MAX_DEGREE + 1]) -> f32 {
    let mut total = 0.0;
    for i in 0..=degree {
        let mut offsets = [0.0; MAX_DEGREE];
        for (l, o) in offsets.iter_mut().enumerate().take(degree) {
            *o = x[i] - x[if l < i { l } else { l + 1 }];
        }
        let means = elementary_means(&offsets, degree);
        let mut factorial = 1.0;
        let mut term = 0.0;
        for j in 0..=degree {
            if j > 0 {
                factorial *= j as f32;
            }
            term += means[j] / (factorial * prob[j]);
        }
        total += (-x[i]).exp() * term;
    }
    total / (degree + 1) as f32
}

pub fn unbiased_ray_marching(
    medium: &Medium,
    seg: &Segment,
    multiplier: f32,
    rng: &mut Pcg,
) -> Estimate {
    let (degree, prob) = power_series_degree(rng);
    let prep = prepare(medium, seg, Importance::Mean);
    let samples = kettunen_sample_count(prep.total, multiplier);
    let mut x = [0.0; MAX_ESTIMATES];
    let lookups = estimate(
        medium,
        seg,
        &prep,
        degree + 1,
        samples,
        Importance::Mean,
        Jitter::Uniform,
        rng,
        &mut x,
    );
    Estimate { value: power_series(&x, degree, &prob), lookups }
}
