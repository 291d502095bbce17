// The tiny MLP, one invocation per record (CPU mirror: src/cpu/mlp.rs): no biases, ReLU hidden
// layers, linear RGB output. Activations stay in private arrays, weights come from storage
// (weights.wgsl). The fallback for networks the tiled passes (mlp_tile.wgsl) do not take.

import package::nirc::config::{ACT_FLOATS, DELTA_FLOATS, DIR_DIMS, FEATURES, HIDDEN, IN_DIMS, LEVELS};
import package::nirc::bindings::{hyper};
import package::nirc::bindings_common::{normalize_to_bounds};
import package::nirc::weights::{weight};
import package::nirc::mlp_layout::{act_base, delta_base, mat_cols, mat_offset, mat_rows};
import package::nirc::encoding::{corner_sum, direction_feature, level_corners};

var<private> acts: array<f32, ACT_FLOATS>;
var<private> deltas: array<f32, DELTA_FLOATS>;
var<private> d_input: array<f32, IN_DIMS>;

// Forward pass of predictor `net` on acts[0..IN_DIMS); fills the hidden activations.
fn mlp_forward(net: u32) -> vec3<f32> {
    var out = vec3<f32>(0.0);
    for (var k = 0u; k <= HIDDEN; k++) {
        let rows = mat_rows(k);
        let cols = mat_cols(k);
        let off = mat_offset(k);
        let a = act_base(k);
        for (var i = 0u; i < rows; i++) {
            var acc = 0.0;
            for (var j = 0u; j < cols; j++) {
                acc += weight(net, off + i * cols + j) * acts[a + j];
            }
            if k < HIDDEN {
                acts[act_base(k + 1u) + i] = select(0.0, acc, acc > 0.0);
            } else {
                out[i] = acc;
            }
        }
    }
    return out;
}

// Backward pass of the High-LR predictor from dL/d(output): fills `deltas` (pre-activation
// gradients of every matrix) and `d_input` (gradient of the encoded input).
fn mlp_backward(d_out: vec3<f32>) {
    deltas[delta_base(HIDDEN)] = d_out.x;
    deltas[delta_base(HIDDEN) + 1u] = d_out.y;
    deltas[delta_base(HIDDEN) + 2u] = d_out.z;
    for (var kk = 0u; kk <= HIDDEN; kk++) {
        let k = HIDDEN - kk;
        let rows = mat_rows(k);
        let cols = mat_cols(k);
        let off = mat_offset(k);
        let db = delta_base(k);
        for (var j = 0u; j < cols; j++) {
            var acc = 0.0;
            for (var i = 0u; i < rows; i++) {
                acc += weight(0u, off + i * cols + j) * deltas[db + i];
            }
            if k == 0u {
                d_input[j] = acc;
            } else {
                // ReLU passes the gradient where its output was positive.
                deltas[delta_base(k - 1u) + j] = select(0.0, acc, acts[act_base(k) + j] > 0.0);
            }
        }
    }
}

fn encode_direction(d: vec3<f32>) {
    for (var i = 0u; i < DIR_DIMS; i++) {
        acts[LEVELS * FEATURES + i] = direction_feature(d, i);
    }
}

// Writes the network input of predictor `net` (0 = High-LR, 1 = EMA) into acts[0..IN_DIMS).
fn encode_input(net: u32, position: vec3<f32>, direction: vec3<f32>) {
    let p = normalize_to_bounds(hyper, position);
    for (var l = 0u; l < LEVELS; l++) {
        let corners = level_corners(l, p);
        for (var k = 0u; k < FEATURES; k++) {
            acts[l * FEATURES + k] = corner_sum(net, corners, k);
        }
    }
    encode_direction(direction);
}
