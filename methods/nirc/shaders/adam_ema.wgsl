// Training pass 3, dense: Adam on every parameter (on the MLP's only, with sparse grid updates:
// adam_sparse.wgsl takes the grid), then the debiased EMA (adam_step.wgsl).
// `check` computes every update without writing and raises the flag on any non-finite value;
// `apply` recomputes and writes the Adam step (w, m, v) only if no pass raised it, and `ema`
// then moves the EMA towards the new weights (its own dispatch, the frame's `nirc::ema`
// system); a bad step leaves no trace.

import package::nirc::config::{DENSE_QUADS};
import package::nirc::bindings_common::{is_finite4};
import package::nirc::grid_write::{mirror_ema, mirror_params};
import package::nirc::adam_step::{MLP_QUADS, Update, adam_m, adam_v, counters, ema, grad, grid_gradient, hyper, params, update};

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

fn update_at(q: u32, g: vec4<f32>, pw: Powers) -> Update {
    return update(q, g, vec4<f32>(pw.b1t), vec4<f32>(pw.b2t));
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
    let u = update_at(q, g, pw);
    return is_finite4(u.g) && is_finite4(u.w) && is_finite4(u.m) && is_finite4(u.v) && is_finite4(ema_of(q, u.w, pw));
}

// Writes quad q's step and returns its new weights.
fn write_update(q: u32, g: vec4<f32>, pw: Powers) -> vec4<f32> {
    let u = update_at(q, g, pw);
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
    for (var q = MLP_QUADS + gid.x; q < DENSE_QUADS; q += stride) {
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
    for (var q = MLP_QUADS + gid.x; q < DENSE_QUADS; q += stride) {
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
    for (var q = MLP_QUADS + gid.x; q < DENSE_QUADS; q += stride) {
        let e = ema_of(q, params[q], pw);
        ema[q] = e;
        mirror_ema(q, e);
    }
}
