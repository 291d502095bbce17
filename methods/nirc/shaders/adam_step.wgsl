// The Adam step and the debiased EMA of one quad of parameters, shared by the dense passes
// (adam_ema.wgsl) and the sparse grid passes (adam_sparse.wgsl); CPU mirror:
// src/cpu/optimizer.rs. The debiased EMA w̄_t = (α w̄_{t-1} (1 - α^{t-1}) + (1 - α) w_t) /
// (1 - α^t) is computed as the convex combination w̄ + β_t (w - w̄), β_t = (1 - α) / (1 - α^t).
//
// Quads of parameters with vec4 loads and stores: on lavapipe every storage access is a loop
// over the SIMD lanes, so a quad costs one such loop where four scalars cost four. The layout
// pads the MLP region and the whole vector to quads (src/layout.rs), so a quad is either all MLP
// weights or all grid entries. The arithmetic is per component, the same as the CPU's.

import package::nirc::types::{Call, CountersAtomic, Hyper};
import package::nirc::config::{MLP_PARAMS};
import package::nirc::fixed_sum_read::{fixed_to_f32};

@group(0) @binding(0) var<storage, read> call: Call;
@group(0) @binding(1) var<storage, read> hyper: Hyper;
@group(0) @binding(2) var<storage, read_write> params: array<vec4<f32>>;
@group(0) @binding(3) var<storage, read_write> ema: array<vec4<f32>>;
@group(0) @binding(4) var<storage, read_write> adam_m: array<vec4<f32>>;
@group(0) @binding(5) var<storage, read_write> adam_v: array<vec4<f32>>;
@group(0) @binding(6) var<storage, read> grad: array<vec4<f32>>;
// Three words (lo, mid, hi) per grid entry, so a quad of entries is three vec4s.
@group(0) @binding(7) var<storage, read> grid_accum: array<vec4<u32>>;
@group(0) @binding(8) var<storage, read_write> counters: CountersAtomic;

const MLP_QUADS: u32 = MLP_PARAMS / 4u;

struct Update {
    w: vec4<f32>,
    m: vec4<f32>,
    v: vec4<f32>,
    g: vec4<f32>,
}

// The mean gradient of grid quad q (q >= MLP_QUADS): its exact fixed-point sums as f32.
fn grid_gradient(q: u32) -> vec4<f32> {
    let b = 3u * (q - MLP_QUADS);
    let a = grid_accum[b];
    let c = grid_accum[b + 1u];
    let d = grid_accum[b + 2u];
    let sums = vec4<f32>(fixed_to_f32(a.x, a.y, a.z), fixed_to_f32(a.w, c.x, c.y), fixed_to_f32(c.z, c.w, d.x), fixed_to_f32(d.y, d.z, d.w));
    return sums * call.inv_n;
}

// Adam on quad q with gradient g and, per component, the step's β1^t and β2^t.
fn update(q: u32, g: vec4<f32>, b1t: vec4<f32>, b2t: vec4<f32>) -> Update {
    let m1 = hyper.beta1 * adam_m[q] + (1.0 - hyper.beta1) * g;
    let v1 = hyper.beta2 * adam_v[q] + (1.0 - hyper.beta2) * (g * g);
    let m_hat = m1 / (1.0 - b1t);
    let v_hat = v1 / (1.0 - b2t);
    let w1 = params[q] - hyper.learning_rate * m_hat / (sqrt(v_hat) + hyper.adam_epsilon);
    return Update(w1, m1, v1, g);
}
