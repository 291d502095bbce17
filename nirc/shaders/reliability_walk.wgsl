// Reliability grid, per-sample rule (the paper's): the owner of each cell (its first sample,
// reliability_accumulate.wgsl) replays the cell's samples in record order,
// X <- λ X + (1 - λ) x for each moment, and leaves the new moments in the cell's accumulator
// words for reliability_update.wgsl (which keeps them unless the step is rolled back). One
// invocation does a cell's whole sequence: deterministic, and the CPU's exact operations.

import package::nirc::bindings::{accum, call, hyper, moments, sample_cells, samples};
import package::nirc::reliability::{ACCUM_COUNT, ACCUM_OWNER, ACCUM_PER_CELL, MOMENTS_CUR, MOMENTS_EMA, MOMENTS_PER_CELL};

fn moment_at(base: u32) -> vec3<f32> {
    return vec3<f32>(moments[base], moments[base + 1u], moments[base + 2u]);
}

fn stage(base: u32, v: vec3<f32>) {
    accum[base] = bitcast<u32>(v.x);
    accum[base + 1u] = bitcast<u32>(v.y);
    accum[base + 2u] = bitcast<u32>(v.z);
}

@compute @workgroup_size(64)
fn main(@builtin(global_invocation_id) gid: vec3<u32>, @builtin(num_workgroups) groups: vec3<u32>) {
    let l = hyper.lambda;
    for (var s = gid.x; s < call.n; s += groups.x * 64u) {
        let cell = sample_cells[s];
        let base = cell * ACCUM_PER_CELL;
        if ~accum[base + ACCUM_OWNER] != s {
            continue;
        }
        let count = accum[base + ACCUM_COUNT];
        let m = cell * MOMENTS_PER_CELL;
        // [M^y, Q^y, M^f_cur, Q^f_cur, C_cur, M^f_ema, Q^f_ema, C_ema], each RGB.
        var my = moment_at(m);
        var qy = moment_at(m + 3u);
        var mc = moment_at(m + MOMENTS_CUR);
        var qc = moment_at(m + MOMENTS_CUR + 3u);
        var cc = moment_at(m + MOMENTS_CUR + 6u);
        var me = moment_at(m + MOMENTS_EMA);
        var qe = moment_at(m + MOMENTS_EMA + 3u);
        var ce = moment_at(m + MOMENTS_EMA + 6u);
        var seen = 0u;
        for (var t = s; t < call.n && seen < count; t++) {
            if sample_cells[t] != cell {
                continue;
            }
            seen++;
            let x = samples[t];
            let y = x.target_rgb.xyz;
            let fc = x.f_cur.xyz;
            let fe = x.f_ema.xyz;
            my = l * my + (1.0 - l) * y;
            qy = l * qy + (1.0 - l) * (y * y);
            mc = l * mc + (1.0 - l) * fc;
            qc = l * qc + (1.0 - l) * (fc * fc);
            cc = l * cc + (1.0 - l) * (y * fc);
            me = l * me + (1.0 - l) * fe;
            qe = l * qe + (1.0 - l) * (fe * fe);
            ce = l * ce + (1.0 - l) * (y * fe);
        }
        stage(base, my);
        stage(base + 3u, qy);
        stage(base + MOMENTS_CUR, mc);
        stage(base + MOMENTS_CUR + 3u, qc);
        stage(base + MOMENTS_CUR + 6u, cc);
        stage(base + MOMENTS_EMA, me);
        stage(base + MOMENTS_EMA + 3u, qe);
        stage(base + MOMENTS_EMA + 6u, ce);
    }
}
