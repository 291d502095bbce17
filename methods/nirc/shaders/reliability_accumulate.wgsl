// Reliability grid, step 1 of an update (one invocation per sample): finds the sample's cell
// and counts it. Per sample (the paper's rule) the sample is pushed onto its cell's list (the
// head, index + 1, in the ACCUM_HEAD word; 0 ends a list); the list's order depends on the threads'
// order, and the list's final head replays the cell's samples in record order
// (reliability_walk.wgsl). Per batch, the sample's 24 quantities (y, y^2, f, f^2, y f per
// predictor, per channel) are added to the cell's exact fixed-point sums. Deterministic.

import package::nirc::bindings::{accum, call, counters, hyper, sample_cells, samples};
import package::nirc::bindings_common::{is_finite};
import package::nirc::fixed_sum::{fixed_add_clamped};
import package::nirc::reliability::{ACCUM_COUNT, ACCUM_HEAD, ACCUM_PER_CELL, MOMENTS_CUR, MOMENTS_EMA, cell_index};

@compute @workgroup_size(64)
fn main(@builtin(global_invocation_id) gid: vec3<u32>, @builtin(num_workgroups) groups: vec3<u32>) {
    var ok = true;
    for (var s = gid.x; s < call.n; s += groups.x * 64u) {
        let sample = samples[s];
        let cell = cell_index(sample.position.xyz);
        let base = cell * ACCUM_PER_CELL;
        atomicAdd(&accum[base + ACCUM_COUNT], 1u);
        if hyper.moments_per_sample == 1u {
            sample_cells[s] = vec2<u32>(cell, atomicExchange(&accum[base + ACCUM_HEAD], s + 1u));
            for (var c = 0u; c < 3u; c++) {
                ok = ok && is_finite(sample.target_rgb[c]) && is_finite(sample.f_cur[c]) && is_finite(sample.f_ema[c]);
            }
            continue;
        }
        for (var c = 0u; c < 3u; c++) {
            let y = sample.target_rgb[c];
            let fc = sample.f_cur[c];
            let fe = sample.f_ema[c];
            ok = fixed_add_clamped(base + 3u * c, y) && ok;
            ok = fixed_add_clamped(base + 3u * (3u + c), y * y) && ok;
            ok = fixed_add_clamped(base + 3u * (MOMENTS_CUR + c), fc) && ok;
            ok = fixed_add_clamped(base + 3u * (MOMENTS_CUR + 3u + c), fc * fc) && ok;
            ok = fixed_add_clamped(base + 3u * (MOMENTS_CUR + 6u + c), y * fc) && ok;
            ok = fixed_add_clamped(base + 3u * (MOMENTS_EMA + c), fe) && ok;
            ok = fixed_add_clamped(base + 3u * (MOMENTS_EMA + 3u + c), fe * fe) && ok;
            ok = fixed_add_clamped(base + 3u * (MOMENTS_EMA + 6u + c), y * fe) && ok;
        }
    }
    if !ok {
        atomicOr(&counters.flag, 1u);
    }
}
