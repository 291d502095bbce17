// Sparse updates of the hash grid (`optimizer.sparse_grid`; CPU mirror: the grid branch of
// src/cpu/cache.rs). tiny-cuda-nn's Adam skips every grid parameter whose gradient is exactly
// zero this step and debiases each with its own step count; here Adam and the EMA both do.
// The training pass marks each grid quad its scatter touched (sparse_mark, generated in
// src/gpu/shaders.rs) and touched_list.wgsl lists the marked quads in ascending order; these
// passes run over that list only, with indirect dispatches sized by it. Per step:
//   clear_touched   zeroes the gradient sums of the previous step's list
//   (the training pass marks the quads it scatters into; touched_list.wgsl lists them)
//   check_grid, apply_grid, ema_grid   Adam's check and apply, then the EMA, over the list

import package::nirc::config::{WG_SIZE};
import package::nirc::bindings_common::{is_finite4};
import package::nirc::grid_write::{mirror_ema, mirror_params};
import package::nirc::adam_step::{MLP_QUADS, Update, adam_m, adam_v, counters, ema, grid_gradient, hyper, params, update};

// Per grid quad, each parameter's committed Adam steps.
@group(0) @binding(11) var<storage, read_write> grid_steps: array<vec4<u32>>;
// (β1^t, β2^t, α^t, 0) by step count t (cpu::optimizer::BiasPowers).
@group(0) @binding(12) var<storage, read> bias_powers: array<vec4<f32>>;
// Grid quads the step touched (relative to the grid's first quad), ascending, each once.
@group(0) @binding(13) var<storage, read> touched: array<u32>;
// The list's length (touched_list.wgsl).
@group(0) @binding(14) var<storage, read> touched_len: u32;
// The gradient sums again, writable (only clear_touched binds them here).
@group(0) @binding(16) var<storage, read_write> grid_accum_out: array<vec4<u32>>;

@compute @workgroup_size(64)
fn clear_touched(@builtin(global_invocation_id) gid: vec3<u32>, @builtin(num_workgroups) groups: vec3<u32>) {
    let stride = groups.x * WG_SIZE;
    // Loaded once: on lavapipe every storage load is a loop over the SIMD lanes.
    let n = touched_len;
    for (var i = gid.x; i < n; i += stride) {
        let r = touched[i];
        grid_accum_out[3u * r] = vec4<u32>(0u);
        grid_accum_out[3u * r + 1u] = vec4<u32>(0u);
        grid_accum_out[3u * r + 2u] = vec4<u32>(0u);
    }
}

// The bias corrections of a quad whose parameters have taken `t` steps (this one included).
struct SparsePowers {
    b1t: vec4<f32>,
    b2t: vec4<f32>,
    // β_t of the EMA per parameter; at t = 1 the EMA starts at the weights (α^{t-1} = 1).
    ema_beta: vec4<f32>,
    first: vec4<bool>,
}

fn sparse_powers(t: vec4<u32>) -> SparsePowers {
    let last = arrayLength(&bias_powers) - 1u;
    let x = bias_powers[min(t.x, last)];
    let y = bias_powers[min(t.y, last)];
    let z = bias_powers[min(t.z, last)];
    let w = bias_powers[min(t.w, last)];
    let at = vec4<f32>(x.z, y.z, z.z, w.z);
    return SparsePowers(vec4<f32>(x.x, y.x, z.x, w.x), vec4<f32>(x.y, y.y, z.y, w.y), (1.0 - hyper.alpha) / (1.0 - at), t == vec4<u32>(1u));
}

// Adam on grid quad r (relative) for the parameters whose gradient is not zero; the others keep
// their values. `moved`: which parameters step.
struct SparseUpdate {
    u: Update,
    moved: vec4<bool>,
    pw: SparsePowers,
}

fn sparse_update(r: u32) -> SparseUpdate {
    let q = MLP_QUADS + r;
    let g = grid_gradient(q);
    let moved = g != vec4<f32>(0.0);
    let t = grid_steps[r] + select(vec4<u32>(0u), vec4<u32>(1u), moved);
    let pw = sparse_powers(t);
    let u = update(q, g, pw.b1t, pw.b2t);
    let kept = Update(select(params[q], u.w, moved), select(adam_m[q], u.m, moved), select(adam_v[q], u.v, moved), g);
    return SparseUpdate(kept, moved, pw);
}

// The EMA of quad q after its weights became `w1`, for the parameters that moved.
fn sparse_ema(q: u32, w1: vec4<f32>, moved: vec4<bool>, pw: SparsePowers) -> vec4<f32> {
    let e0 = ema[q];
    let e1 = select(e0 + pw.ema_beta * (w1 - e0), w1, pw.first);
    return select(e0, e1, moved);
}

@compute @workgroup_size(64)
fn check_grid(@builtin(global_invocation_id) gid: vec3<u32>, @builtin(num_workgroups) groups: vec3<u32>) {
    var ok = true;
    let stride = groups.x * WG_SIZE;
    let n = touched_len;
    for (var i = gid.x; i < n; i += stride) {
        let r = touched[i];
        let s = sparse_update(r);
        let e = sparse_ema(MLP_QUADS + r, s.u.w, s.moved, s.pw);
        ok = is_finite4(s.u.g) && is_finite4(s.u.w) && is_finite4(s.u.m) && is_finite4(s.u.v) && is_finite4(e) && ok;
    }
    if !ok {
        atomicOr(&counters.flag, 1u);
    }
}

@compute @workgroup_size(64)
fn apply_grid(@builtin(global_invocation_id) gid: vec3<u32>, @builtin(num_workgroups) groups: vec3<u32>) {
    if atomicLoad(&counters.flag) != 0u {
        return;
    }
    let stride = groups.x * WG_SIZE;
    let n = touched_len;
    for (var i = gid.x; i < n; i += stride) {
        let r = touched[i];
        let q = MLP_QUADS + r;
        let s = sparse_update(r);
        params[q] = s.u.w;
        adam_m[q] = s.u.m;
        adam_v[q] = s.u.v;
        grid_steps[r] += select(vec4<u32>(0u), vec4<u32>(1u), s.moved);
        mirror_params(q, s.u.w);
    }
}

@compute @workgroup_size(64)
fn ema_grid(@builtin(global_invocation_id) gid: vec3<u32>, @builtin(num_workgroups) groups: vec3<u32>) {
    if atomicLoad(&counters.flag) != 0u {
        return;
    }
    let stride = groups.x * WG_SIZE;
    let n = touched_len;
    for (var i = gid.x; i < n; i += stride) {
        let r = touched[i];
        let q = MLP_QUADS + r;
        // The steps were counted by apply_grid: the EMA debiases with the new counts.
        let moved = grid_gradient(q) != vec4<f32>(0.0);
        let e = sparse_ema(q, params[q], moved, sparse_powers(grid_steps[r]));
        ema[q] = e;
        mirror_ema(q, e);
    }
}
