// Training pass 3: Adam on every parameter, then the debiased EMA
// w̄_t = (α w̄_{t-1} (1 - α^{t-1}) + (1 - α) w_t) / (1 - α^t) (CPU mirror: src/cpu/optimizer.rs).
// `check` computes every update without writing and raises the flag on any non-finite value;
// `apply` recomputes and writes the Adam step (w, m, v) only if no pass raised it, and `ema`
// then moves the EMA towards the new weights (its own dispatch, the frame's `nirc::ema`
// system); a bad step leaves no trace.

import package::nirc::types::{Call, CountersAtomic, Hyper};
import package::nirc::config::{MLP_PARAMS, TOTAL_PARAMS};
import package::nirc::bindings_common::{is_finite};
import package::nirc::fixed_sum_read::{fixed_to_f32};

@group(0) @binding(0) var<uniform> call: Call;
@group(0) @binding(1) var<uniform> hyper: Hyper;
@group(0) @binding(2) var<storage, read_write> params: array<f32>;
@group(0) @binding(3) var<storage, read_write> ema: array<f32>;
@group(0) @binding(4) var<storage, read_write> adam_m: array<f32>;
@group(0) @binding(5) var<storage, read_write> adam_v: array<f32>;
@group(0) @binding(6) var<storage, read> grad: array<f32>;
@group(0) @binding(7) var<storage, read> grid_accum: array<u32>;
@group(0) @binding(8) var<storage, read_write> counters: CountersAtomic;

struct Update {
    w: f32,
    m: f32,
    v: f32,
    g: f32,
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

fn update(i: u32, pw: Powers) -> Update {
    var g: f32;
    if i < MLP_PARAMS {
        g = grad[i];
    } else {
        let b = 3u * (i - MLP_PARAMS);
        g = fixed_to_f32(grid_accum[b], grid_accum[b + 1u], grid_accum[b + 2u]) * call.inv_n;
    }
    let m1 = hyper.beta1 * adam_m[i] + (1.0 - hyper.beta1) * g;
    let v1 = hyper.beta2 * adam_v[i] + (1.0 - hyper.beta2) * (g * g);
    let m_hat = m1 / (1.0 - pw.b1t);
    let v_hat = v1 / (1.0 - pw.b2t);
    let w1 = params[i] - hyper.learning_rate * m_hat / (sqrt(v_hat) + hyper.adam_epsilon);
    return Update(w1, m1, v1, g);
}

/// The EMA of parameter `i` once the weights are `w1`: the debiased EMA as the convex
/// combination w̄ + β_t (w - w̄), β_t = (1 - α) / (1 - α^t) (same as the notes' formula, exact
/// on constants); at t = 1 it is w_1. (`apply` does not need it, so `update` does not read the
/// EMA: on lavapipe an unused storage load is still paid.)
fn ema_of(i: u32, w1: f32, pw: Powers) -> f32 {
    var e1 = w1;
    if !pw.first {
        e1 = ema[i] + pw.ema_beta * (w1 - ema[i]);
    }
    return e1;
}

@compute @workgroup_size(64)
fn check(@builtin(global_invocation_id) gid: vec3<u32>, @builtin(num_workgroups) groups: vec3<u32>) {
    var ok = true;
    let pw = powers();
    for (var i = gid.x; i < TOTAL_PARAMS; i += groups.x * 64u) {
        let u = update(i, pw);
        ok = ok && is_finite(u.g) && is_finite(u.w) && is_finite(u.m) && is_finite(u.v) && is_finite(ema_of(i, u.w, pw));
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
    for (var i = gid.x; i < TOTAL_PARAMS; i += groups.x * 64u) {
        let u = update(i, pw);
        params[i] = u.w;
        adam_m[i] = u.m;
        adam_v[i] = u.v;
    }
}

@compute @workgroup_size(64)
fn ema_update(@builtin(global_invocation_id) gid: vec3<u32>, @builtin(num_workgroups) groups: vec3<u32>) {
    if atomicLoad(&counters.flag) != 0u {
        return;
    }
    let pw = powers();
    for (var i = gid.x; i < TOTAL_PARAMS; i += groups.x * 64u) {
        ema[i] = ema_of(i, params[i], pw);
    }
}
