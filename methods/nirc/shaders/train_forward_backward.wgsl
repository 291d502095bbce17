// Training pass 1 (one thread per record): encode, forward of both predictors, relative L2
// loss, backward of the High-LR predictor. Writes the activations and pre-activation gradients
// for the weight-gradient pass, scatters the hash-grid gradients into exact fixed-point sums
// (order-independent), and the (y, f_cur, f_ema) sample for the reliability grid.

import package::nirc::types::{ReliabilitySample};
import package::nirc::config::{ACT_FLOATS, DELTA_FLOATS, FEATURES, LEVELS, MLP_PARAMS, SCRATCH_STRIDE};
import package::nirc::bindings::{call, counters, hyper, losses, records, samples, scratch_set};
import package::nirc::bindings_common::{is_finite, normalize_to_bounds};
import package::nirc::fixed_sum::{fixed_add};
import package::nirc::sparse_mark::{mark_touched};
import package::nirc::loss::{relative_l2};
import package::nirc::encoding::{level_corners};
import package::nirc::mlp::{acts, d_input, deltas, encode_input, mlp_backward, mlp_forward};

@compute @workgroup_size(64)
fn main(@builtin(global_invocation_id) gid: vec3<u32>, @builtin(local_invocation_index) lid: u32) {
    let r = gid.x;
    let in_range = r < call.n;
    let rec = records[min(r, call.n - 1u)];
    let pos = rec.position.xyz;
    let dir = rec.direction.xyz;

    var f_ema = vec3<f32>(0.0);
    if in_range {
        encode_input(1u, pos, dir);
        f_ema = mlp_forward(1u);
    }
    if !in_range {
        return;
    }
    encode_input(0u, pos, dir);
    let f = mlp_forward(0u);
    let y = rec.target_rgb.xyz;

    let l2 = relative_l2(f, y);
    let loss = l2.w;
    let d_out = l2.xyz;
    losses[r] = loss;
    var ok = is_finite(loss);

    mlp_backward(d_out);
    let base = r * SCRATCH_STRIDE;
    for (var i = 0u; i < ACT_FLOATS; i++) {
        scratch_set(base + i, acts[i]);
    }
    for (var i = 0u; i < DELTA_FLOATS; i++) {
        scratch_set(base + ACT_FLOATS + i, deltas[i]);
    }

    let p = normalize_to_bounds(hyper, pos);
    for (var l = 0u; l < LEVELS; l++) {
        let corners = level_corners(l, p);
        for (var c = 0u; c < 8u; c++) {
            mark_touched(corners.index[c]);
            for (var k = 0u; k < FEATURES; k++) {
                let g = corners.weight[c] * d_input[l * FEATURES + k];
                ok = fixed_add(3u * (corners.index[c] + k - MLP_PARAMS), g) && ok;
            }
        }
    }
    if !ok {
        atomicOr(&counters.flag, 1u);
    }
    samples[r] = ReliabilitySample(rec.position, rec.target_rgb, vec4<f32>(f, 0.0), vec4<f32>(f_ema, 0.0));
}
