// Stages both predictors' MLP weights for the register-form inference (src/gpu/lane.rs): one
// invocation per vec4, predictor `net` at net * LANE_W_VEC4, matrix m as W^T by output quads:
// staged[base_m + k * quads + q][c] = W_m[4q + c][k], zero past the last output.

import package::nirc::config::{HIDDEN};
import package::nirc::lane::{LANE_BASE, LANE_W_VEC4};
import package::nirc::mlp_layout::{mat_cols, mat_offset, mat_rows};
import package::nirc::weights::{weight};

@group(0) @binding(9) var<storage, read_write> staged: array<vec4<f32>>;

@compute @workgroup_size(64)
fn main(@builtin(global_invocation_id) gid: vec3<u32>) {
    let i = gid.x;
    if i >= 2u * LANE_W_VEC4 {
        return;
    }
    let net = i / LANE_W_VEC4;
    let e = i % LANE_W_VEC4;
    var m = 0u;
    while m < HIDDEN && e >= LANE_BASE[m + 1u] {
        m++;
    }
    let rows = mat_rows(m);
    let cols = mat_cols(m);
    let quads = (rows + 3u) / 4u;
    let local = e - LANE_BASE[m];
    let k = local / quads;
    let o = (local % quads) * 4u;
    var v = vec4<f32>(0.0);
    for (var c = 0u; c < 4u; c++) {
        if o + c < rows {
            v[c] = weight(net, mat_offset(m) + (o + c) * cols + k);
        }
    }
    staged[i] = v;
}
