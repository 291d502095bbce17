// Reliability grid, last step of an update (one thread per cell that received samples): per
// sample, the moments staged by reliability_walk.wgsl; per batch, one move towards the batch
// mean, X <- λ X + (1 - λ) mean. Skipped when the step is being rolled back.

import package::nirc::config::{CELL_COUNT};
import package::nirc::bindings::{accum, counters, hyper, moments};
import package::nirc::fixed_sum_read::{fixed_to_f32};
import package::nirc::reliability::{ACCUM_COUNT, ACCUM_PER_CELL, MOMENTS_PER_CELL};

@compute @workgroup_size(64)
fn main(@builtin(global_invocation_id) gid: vec3<u32>, @builtin(num_workgroups) groups: vec3<u32>) {
    if atomicLoad(&counters.flag) != 0u {
        return;
    }
    for (var cell = gid.x; cell < CELL_COUNT; cell += groups.x * 64u) {
        let base = cell * ACCUM_PER_CELL;
        let count = accum[base + ACCUM_COUNT];
        if count == 0u {
            continue;
        }
        for (var q = 0u; q < MOMENTS_PER_CELL; q++) {
            let i = cell * MOMENTS_PER_CELL + q;
            if hyper.moments_per_sample == 1u {
                moments[i] = bitcast<f32>(accum[base + q]);
            } else {
                let mean = fixed_to_f32(accum[base + 3u * q], accum[base + 3u * q + 1u], accum[base + 3u * q + 2u]) / f32(count);
                moments[i] = hyper.lambda * moments[i] + (1.0 - hyper.lambda) * mean;
            }
        }
    }
}
