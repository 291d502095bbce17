// Training pass 2: MLP weight gradients dW_k[i][j] = sum_r delta_k[r][i] * a_k[r][j] without
// float atomics: `partial_sums` sums each chunk of CHUNK records in record order (one thread per
// weight and chunk), `reduce` sums the chunks in chunk order and divides by the batch size.
// Deterministic, and the CPU reference sums in the same order.

import package::nirc::types::{Call};
import package::nirc::config::{ACT_FLOATS, CHUNK, HIDDEN, MLP_PARAMS, MLP_WEIGHTS, SCRATCH_STRIDE};
import package::nirc::mlp_layout::{act_base, delta_base, mat_cols, mat_offset};

@group(0) @binding(0) var<storage, read> call: Call;
@group(0) @binding(1) var<storage, read> scratch: array<f32>;
@group(0) @binding(2) var<storage, read_write> partials: array<f32>;
@group(0) @binding(3) var<storage, read_write> grad: array<f32>;

fn matrix_of(w: u32) -> u32 {
    var k = 0u;
    while k < HIDDEN && w >= mat_offset(k + 1u) {
        k++;
    }
    return k;
}

@compute @workgroup_size(64)
fn partial_sums(@builtin(global_invocation_id) gid: vec3<u32>, @builtin(num_workgroups) groups: vec3<u32>) {
    let total = MLP_PARAMS * call.num_chunks;
    for (var t = gid.x; t < total; t += groups.x * 64u) {
        let chunk = t / MLP_PARAMS;
        let w = t % MLP_PARAMS;
        let k = matrix_of(w);
        let cols = mat_cols(k);
        let local = w - mat_offset(k);
        let i = local / cols;
        let j = local % cols;
        let r0 = chunk * CHUNK;
        let r1 = min(r0 + CHUNK, call.n);
        let d = ACT_FLOATS + delta_base(k) + i;
        let a = act_base(k) + j;
        var s = 0.0;
        // The quad padding after the last matrix (layout.rs) has no gradient.
        let r_end = select(r0, r1, w < MLP_WEIGHTS);
        for (var r = r0; r < r_end; r++) {
            let b = r * SCRATCH_STRIDE;
            s += scratch[b + d] * scratch[b + a];
        }
        partials[t] = s;
    }
}

@compute @workgroup_size(64)
fn reduce(@builtin(global_invocation_id) gid: vec3<u32>, @builtin(num_workgroups) groups: vec3<u32>) {
    for (var w = gid.x; w < MLP_PARAMS; w += groups.x * 64u) {
        var g = 0.0;
        for (var c = 0u; c < call.num_chunks; c++) {
            g += partials[c * MLP_PARAMS + w];
        }
        grad[w] = g * call.inv_n;
    }
}
