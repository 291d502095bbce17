// Reliability grid lookups (CPU mirror: src/reliability.rs): the hashed voxel cell of a
// position, eq. 3 averaged over RGB, the relative squared error, the scale mismatch, and the
// blend weight of the High-LR predictor.

import package::nirc::config::{CELL_COUNT};
import package::nirc::bindings::{hyper};
import package::nirc::bindings_common::{normalize_to_bounds, spatial_hash};

// Per cell: [M^y, Q^y, M^f_cur, Q^f_cur, C_cur, M^f_ema, Q^f_ema, C_ema] x RGB.
const MOMENTS_PER_CELL: u32 = 24u;
// Per cell accumulator: 24 fixed-point sums of 3 words (per batch) or 24 staged moments (per
// sample), the head of the cell's list of samples (index + 1, per sample), then the sample
// count.
const ACCUM_PER_CELL: u32 = 73u;
const ACCUM_HEAD: u32 = 71u;
const ACCUM_COUNT: u32 = 72u;
const MOMENTS_CUR: u32 = 6u;
const MOMENTS_EMA: u32 = 15u;

fn cell_index(position: vec3<f32>) -> u32 {
    let p = normalize_to_bounds(hyper, position);
    let r = hyper.reliability_resolution;
    let v = min(vec3<u32>(p * f32(r)), vec3<u32>(r - 1u));
    return spatial_hash(v) & (CELL_COUNT - 1u);
}

// r̄ = mean over RGB of c / sqrt((s^y + ε)(s^f + ε)).
fn mean_correlation(my: vec3<f32>, qy: vec3<f32>, mf: vec3<f32>, qf: vec3<f32>, cyf: vec3<f32>) -> f32 {
    var sum = 0.0;
    for (var c = 0u; c < 3u; c++) {
        let sy = max(qy[c] - my[c] * my[c], 0.0);
        let sf = max(qf[c] - mf[c] * mf[c], 0.0);
        let cov = cyf[c] - my[c] * mf[c];
        sum += cov / sqrt((sy + hyper.reliability_epsilon) * (sf + hyper.reliability_epsilon));
    }
    return sum / 3.0;
}

// e = mean over RGB of max(Q^y - 2 C^{y,f} + Q^f, 0) / (Q^y + ε): the EMA of (y - f)², relative.
fn mean_relative_error(qy: vec3<f32>, qf: vec3<f32>, cyf: vec3<f32>) -> f32 {
    var sum = 0.0;
    for (var c = 0u; c < 3u; c++) {
        let squared_error = max(qy[c] - 2.0 * cyf[c] + qf[c], 0.0);
        sum += squared_error / (qy[c] + hyper.reliability_epsilon);
    }
    return sum / 3.0;
}

// σ = (e_EMA + ε) / (e_cur + e_EMA + 2ε) (mode 6 once warmed up).
fn inverse_error_weight(e_cur: f32, e_ema: f32) -> f32 {
    let eps = hyper.reliability_epsilon;
    return (e_ema + eps) / (e_cur + e_ema + 2.0 * eps);
}

// d = |ln ρ|, ρ = (max(Σ_c C^{y,f}_c, 0) + ε) / (Σ_c Q^f_c + ε): the gain from f to y through
// the origin.
fn scale_mismatch(qf: vec3<f32>, cyf: vec3<f32>) -> f32 {
    let eps = hyper.reliability_epsilon;
    var c_sum = 0.0;
    var q_sum = 0.0;
    for (var c = 0u; c < 3u; c++) {
        q_sum += qf[c];
        c_sum += cyf[c];
    }
    return abs(log((max(c_sum, 0.0) + eps) / (q_sum + eps)));
}

// Modes: 0 EMA-only, 1 High-LR only, 2 blend, 3 switch, 6 blend by the relative errors (then
// r_cur, r_ema hold e_cur, e_ema), 7 by the scale mismatches (they hold d_cur, d_ema). Markers
// are off during warm-up.
fn high_lr_weight(mode: u32, grid_updates: u32, r_cur: f32, r_ema: f32) -> f32 {
    if mode == 0u {
        return 0.0;
    }
    if mode == 1u {
        return 1.0;
    }
    if grid_updates < hyper.warmup {
        return 0.0;
    }
    if mode == 2u {
        return 1.0 / (1.0 + exp(-hyper.kappa * (r_cur - r_ema)));
    }
    if mode == 6u {
        return inverse_error_weight(r_cur, r_ema);
    }
    if mode == 7u {
        return 1.0 / (1.0 + exp(-hyper.kappa * (r_ema - r_cur)));
    }
    return select(0.0, 1.0, r_cur > r_ema);
}
