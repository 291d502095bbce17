// The transmittance estimators by id (media::transmittance::Estimator::gpu_id): naive and
// Kettunen's biased exp(−X), unbiased ray marching (power series, degree ≤ 8), the jackknife
// (fixed N, or N tied to the importance: Fig. 8d).

import package::media::types::{RaySegment};
import package::media::media_rng::{media_rand};
import package::media::media_jackknife::{jackknife};
import package::media::media_tracking::{ratio_tracking, track_length};
import package::media::media_optical_depth::{kettunen_sample_count, od_estimate, od_prepare, od_x, tied_sample_count};

const EST_TRACK_LENGTH: u32 = 0u;
const EST_RATIO_TRACKING: u32 = 1u;
const EST_BIASED_RAY_MARCHING: u32 = 2u;
const EST_UNBIASED_RAY_MARCHING: u32 = 3u;
const EST_NAIVE: u32 = 4u;
const EST_JACKKNIFE: u32 = 5u;
const EST_JACKKNIFE_TIED: u32 = 6u;
const MAX_DEGREE: u32 = 8u;

var<private> urm_prob: array<f32, 9>;

// Bhanot–Kennedy roulette with p_Z = 0.9, at least order 2, c = 2 (media::unbiased_ray_marching).
fn power_series_degree(rng: ptr<function, u32>) -> u32 {
    for (var k = 0u; k <= MAX_DEGREE; k++) {
        urm_prob[k] = 1.0;
    }
    let u = media_rand(rng);
    var p = 1.0 - 0.9;
    if p <= u {
        return 0u;
    }
    urm_prob[1] = p;
    urm_prob[2] = p;
    for (var k = 3u; k <= MAX_DEGREE; k++) {
        p *= min(2.0 / f32(k), 1.0);
        if p <= u {
            return k - 1u;
        }
        urm_prob[k] = p;
    }
    return MAX_DEGREE;
}

fn power_series(degree: u32) -> f32 {
    var total = 0.0;
    for (var i = 0u; i <= degree; i++) {
        // Elementary means of the offsets X_i − X_l, l ≠ i (Kettunen et al.'s recursion).
        var m: array<f32, 9>;
        m[0] = 1.0;
        for (var k = 1u; k <= MAX_DEGREE; k++) {
            m[k] = 0.0;
        }
        for (var n = 0u; n < degree; n++) {
            let xn = od_x[i] - od_x[select(n + 1u, n, n < i)];
            for (var k = n + 1u; k >= 1u; k--) {
                m[k] += f32(k) / f32(n + 1u) * (m[k - 1u] * xn - m[k]);
            }
        }
        var factorial = 1.0;
        var term = 0.0;
        for (var j = 0u; j <= degree; j++) {
            if j > 0u {
                factorial *= f32(j);
            }
            term += m[j] / (factorial * urm_prob[j]);
        }
        total += exp(-od_x[i]) * term;
    }
    return total / f32(degree + 1u);
}

fn estimate_transmittance(s: RaySegment, kind: u32, samples: u32, multiplier: f32, rng: ptr<function, u32>) -> f32 {
    switch kind {
        case EST_TRACK_LENGTH: {
            return track_length(s, rng);
        }
        case EST_RATIO_TRACKING: {
            return ratio_tracking(s, rng);
        }
        case EST_BIASED_RAY_MARCHING: {
            let prep = od_prepare(s, false);
            od_estimate(s, prep, 1u, kettunen_sample_count(prep.x, multiplier), false, false, rng);
            return exp(-od_x[0]);
        }
        case EST_UNBIASED_RAY_MARCHING: {
            let degree = power_series_degree(rng);
            let prep = od_prepare(s, false);
            od_estimate(s, prep, degree + 1u, kettunen_sample_count(prep.x, multiplier), false, false, rng);
            return power_series(degree);
        }
        case EST_NAIVE: {
            let prep = od_prepare(s, true);
            od_estimate(s, prep, 1u, samples, true, true, rng);
            return exp(-od_x[0]);
        }
        case EST_JACKKNIFE_TIED: {
            // Fig. 8d: N tied to the importance, F_Δ = `multiplier` (the step).
            let prep = od_prepare(s, true);
            od_estimate(s, prep, 2u, tied_sample_count(prep.x, multiplier), true, true, rng);
            return jackknife(od_x[0], od_x[1]);
        }
        default: {
            let prep = od_prepare(s, true);
            od_estimate(s, prep, 2u, samples, true, true, rng);
            return jackknife(od_x[0], od_x[1]);
        }
    }
}
