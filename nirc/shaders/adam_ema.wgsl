// Training pass 3: Adam on every parameter, then the debiased EMA
// w̄_t = (α w̄_{t-1} (1 - α^{t-1}) + (1 - α) w_t) / (1 - α^t) (CPU mirror: src/cpu/optimizer.rs).
// `check` computes every update without writing and raises the flag on any non-finite value;
// `apply` recomputes and writes the Adam step (w, m, v) only if no pass raised it, and `ema`
// then moves the EMA towards the new weights (its own dispatch, the frame's `nirc::ema`
// system); a bad step leaves no trace.
//
// Each invocation works on quads of parameters with vec4 loads and stores: on lavapipe every
// storage access is a loop over the SIMD lanes, so a quad costs one such loop where four
// scalars cost four. The layout pads the MLP region and the whole vector to quads
// (src/layout.rs), so a quad is either all MLP weights or all grid entries. The arithmetic is
// per component, the same as the CPU's.

import package::nirc::types::{Call, CountersAtomic, Hyper};
import package::nirc::config::{MLP_PARAMS, TOTAL_PARAMS};
import package::nirc::bindings_common::{is_finite4};
import package::nirc::fixed_sum_read::{fixed_to_f32};
import package::nirc::grid_write::{mirror_ema, mirror_params};

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
const QUADS: u32 = TOTAL_PARAMS / 4u;

struct Update {
    w: vec4<f32>,
    m: vec4<f32>,
    v: vec4<f32>,
    g: vec4<f32>,
}

// The step's bias corrections, read from `counters` once per invocation: on lavapipe every
// storage load is a loop over the SIMD lanes, and the compiler cannot hoist these out of the
// parameter loop past the writes to other buffers.
struct Powers {
    b1t: f32,
    b2t: f32,
    // β_t of the EMA; `first` when α^{t-1} = 1 (the EMA starts at the weights).
    ema_beta: f32,
    first: bool,
}

fn powers() -> Powers {
    let at = counters.alpha_pow * hyper.alpha;
    return Powers(counters.beta1_pow * hyper.beta1, counters.beta2_pow * hyper.beta2, (1.0 - hyper.alpha) / (1.0 - at), counters.alpha_pow == 1.0);
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

fn update(q: u32, g: vec4<f32>, pw: Powers) -> Update {
    let m1 = hyper.beta1 * adam_m[q] + (1.0 - hyper.beta1) * g;
    let v1 = hyper.beta2 * adam_v[q] + (1.0 - hyper.beta2) * (g * g);
    let m_hat = m1 / (1.0 - pw.b1t);
    let v_hat = v1 / (1.0 - pw.b2t);
    let w1 = params[q] - hyper.learning_rate * m_hat / (sqrt(v_hat) + hyper.adam_epsilon);
    return Update(w1, m1, v1, g);
}

/// The EMA of quad `q` once the weights are `w1`: the debiased EMA as the convex combination
/// w̄ + β_t (w - w̄), β_t = (1 - α) / (1 - α^t) (same as the notes' formula, exact on
/// constants); at t = 1 it is w_1. (`apply` does not need it, so `update` does not read the
/// EMA: on lavapipe an unused storage load is still paid.)
fn ema_of(q: u32, w1: vec4<f32>, pw: Powers) -> vec4<f32> {
    var e1 = w1;
    if !pw.first {
        let e0 = ema[q];
        e1 = e0 + pw.ema_beta * (w1 - e0);
    }
    return e1;
}

fn finite_update(q: u32, g: vec4<f32>, pw: Powers) -> bool {
    let u = update(q, g, pw);
    return is_finite4(u.g) && is_finite4(u.w) && is_finite4(u.m) && is_finite4(u.v) && is_finite4(ema_of(q, u.w, pw));
}

// Writes quad q's step and returns its new weights.
fn write_update(q: u32, g: vec4<f32>, pw: Powers) -> vec4<f32> {
    let u = update(q, g, pw);
    params[q] = u.w;
    adam_m[q] = u.m;
    adam_v[q] = u.v;
    return u.w;
}

// Two loops, the MLP's quads and then the grid's, so that no quad loads both gradients.
@compute @workgroup_size(64)
fn check(@builtin(global_invocation_id) gid: vec3<u32>, @builtin(num_workgroups) groups: vec3<u32>) {
    var ok = true;
    let pw = powers();
    let stride = groups.x * 64u;
    for (var q = gid.x; q < MLP_QUADS; q += stride) {
        ok = finite_update(q, grad[q], pw) && ok;
    }
    for (var q = MLP_QUADS + gid.x; q < QUADS; q += stride) {
        ok = finite_update(q, grid_gradient(q), pw) && ok;
    }
    if !ok {
        atomicOr(&counters.flag, 1u);
    }
}

@compute @workgroup_size(64)
fn apply(@builtin(global_invocation_id) gid: vec3<u32>, @builtin(num_workgroups) groups: vec3<u32>) {
    if atomicLoad(&counters.flag) != 0u {
        return;
    }
    let pw = powers();
    let stride = groups.x * 64u;
    for (var q = gid.x; q < MLP_QUADS; q += stride) {
        _ = write_update(q, grad[q], pw);
    }
    // Grid quads also go to the register form's texture mirror (src/gpu/grid_textures.rs).
    for (var q = MLP_QUADS + gid.x; q < QUADS; q += stride) {
        mirror_params(q, write_update(q, grid_gradient(q), pw));
    }
}

@compute @workgroup_size(64)
fn ema_update(@builtin(global_invocation_id) gid: vec3<u32>, @builtin(num_workgroups) groups: vec3<u32>) {
    if atomicLoad(&counters.flag) != 0u {
        return;
    }
    let pw = powers();
    let stride = groups.x * 64u;
    for (var q = gid.x; q < MLP_QUADS; q += stride) {
        ema[q] = ema_of(q, params[q], pw);
    }
    for (var q = MLP_QUADS + gid.x; q < QUADS; q += stride) {
        let e = ema_of(q, params[q], pw);
        ema[q] = e;
        mirror_ema(q, e);
    }
}
