// Reliability grid, per-sample rule (the paper's): the head of each cell's list of samples
// (reliability_accumulate.wgsl) replays the cell's samples in record order,
// X <- λ X + (1 - λ) x for each moment, and leaves the new moments in the cell's accumulator
// words for reliability_update.wgsl (which keeps them unless the step is rolled back). One
// invocation does a cell's whole sequence: deterministic, and the CPU's exact operations.
//
// The list is in no particular order, so the walker puts it in record order itself: for a cell
// of k samples, k passes over the list each take the smallest index not yet replayed (k² link
// loads). Where k² exceeds the batch, it instead scans the batch from the cell's first sample
// (at most n loads), which is what every cell did before the lists: a scan costs the span of
// the cell's samples in the batch, about n for most cells, and lavapipe runs each storage load
// as a loop over its lanes.

import package::nirc::bindings::{accum, call, hyper, moments, sample_cells, samples};
import package::nirc::reliability::{ACCUM_COUNT, ACCUM_HEAD, ACCUM_PER_CELL, MOMENTS_CUR, MOMENTS_EMA, MOMENTS_PER_CELL};
import package::nirc::types::{ReliabilitySample};

// [M^y, Q^y, M^f_cur, Q^f_cur, C_cur, M^f_ema, Q^f_ema, C_ema], each RGB.
struct Moments {
    my: vec3<f32>,
    qy: vec3<f32>,
    mc: vec3<f32>,
    qc: vec3<f32>,
    cc: vec3<f32>,
    me: vec3<f32>,
    qe: vec3<f32>,
    ce: vec3<f32>,
}

fn moment_at(base: u32) -> vec3<f32> {
    return vec3<f32>(moments[base], moments[base + 1u], moments[base + 2u]);
}

fn stage(base: u32, v: vec3<f32>) {
    accum[base] = bitcast<u32>(v.x);
    accum[base + 1u] = bitcast<u32>(v.y);
    accum[base + 2u] = bitcast<u32>(v.z);
}

// One sample's step of every moment's EMA.
fn absorb(a: Moments, x: ReliabilitySample) -> Moments {
    let l = hyper.lambda;
    let y = x.target_rgb.xyz;
    let fc = x.f_cur.xyz;
    let fe = x.f_ema.xyz;
    var b: Moments;
    b.my = l * a.my + (1.0 - l) * y;
    b.qy = l * a.qy + (1.0 - l) * (y * y);
    b.mc = l * a.mc + (1.0 - l) * fc;
    b.qc = l * a.qc + (1.0 - l) * (fc * fc);
    b.cc = l * a.cc + (1.0 - l) * (y * fc);
    b.me = l * a.me + (1.0 - l) * fe;
    b.qe = l * a.qe + (1.0 - l) * (fe * fe);
    b.ce = l * a.ce + (1.0 - l) * (y * fe);
    return b;
}

@compute @workgroup_size(64)
fn main(@builtin(global_invocation_id) gid: vec3<u32>, @builtin(num_workgroups) groups: vec3<u32>) {
    for (var s = gid.x; s < call.n; s += groups.x * 64u) {
        let cell = sample_cells[s].x;
        let base = cell * ACCUM_PER_CELL;
        if accum[base + ACCUM_HEAD] != s + 1u {
            continue;
        }
        let count = accum[base + ACCUM_COUNT];
        let m = cell * MOMENTS_PER_CELL;
        var mo = Moments(moment_at(m), moment_at(m + 3u), moment_at(m + MOMENTS_CUR), moment_at(m + MOMENTS_CUR + 3u), moment_at(m + MOMENTS_CUR + 6u), moment_at(m + MOMENTS_EMA), moment_at(m + MOMENTS_EMA + 3u), moment_at(m + MOMENTS_EMA + 6u));
        if count * count <= call.n {
            var lo = 0u;
            for (var j = 0u; j < count; j++) {
                var next = 0xffffffffu;
                var link = s + 1u;
                for (var i = 0u; i < count; i++) {
                    let t = link - 1u;
                    if t >= lo && t < next {
                        next = t;
                    }
                    link = sample_cells[t].y;
                }
                mo = absorb(mo, samples[next]);
                lo = next + 1u;
            }
        } else {
            var first = s;
            var link = sample_cells[s].y;
            for (var i = 1u; i < count; i++) {
                first = min(first, link - 1u);
                link = sample_cells[link - 1u].y;
            }
            var seen = 0u;
            for (var t = first; t < call.n && seen < count; t++) {
                if sample_cells[t].x != cell {
                    continue;
                }
                seen++;
                mo = absorb(mo, samples[t]);
            }
        }
        stage(base, mo.my);
        stage(base + 3u, mo.qy);
        stage(base + MOMENTS_CUR, mo.mc);
        stage(base + MOMENTS_CUR + 3u, mo.qc);
        stage(base + MOMENTS_CUR + 6u, mo.cc);
        stage(base + MOMENTS_EMA, mo.me);
        stage(base + MOMENTS_EMA + 3u, mo.qe);
        stage(base + MOMENTS_EMA + 6u, mo.ce);
    }
}
