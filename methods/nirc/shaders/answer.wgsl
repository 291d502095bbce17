// The cache's answer to one query (CPU mirror: CpuCache::infer): σ from the query's
// reliability cell (mode 5: the call's fixed σ; 6: from the relative errors; 7: from the scale
// mismatches), then max(0, (1 - σ) f_EMA + σ f_cur) with σ in .w. Mode 4 (diagnostics)
// answers (r̄_cur, r̄_EMA, σ of the blend, 1 once warmed up). Reads the pass's `hyper`,
// `moments`, `counters` and `answers` (package::nirc::bindings).

import package::nirc::bindings::{answers, call, counters, hyper, moments};
import package::nirc::reliability::{MOMENTS_CUR, MOMENTS_EMA, MOMENTS_PER_CELL, cell_index, high_lr_weight, mean_correlation, mean_relative_error, scale_mismatch};

fn moment3(base: u32) -> vec3<f32> {
    return vec3<f32>(moments[base], moments[base + 1u], moments[base + 2u]);
}

fn write_answer(qi: u32, pos: vec3<f32>, mode: u32, f_ema: vec3<f32>, f_cur: vec3<f32>) {
    var r_cur = 0.0;
    var r_ema = 0.0;
    if mode == 2u || mode == 3u || mode == 4u {
        let b = cell_index(pos) * MOMENTS_PER_CELL;
        let my = moment3(b);
        let qy = moment3(b + 3u);
        r_cur = mean_correlation(my, qy, moment3(b + MOMENTS_CUR), moment3(b + MOMENTS_CUR + 3u), moment3(b + MOMENTS_CUR + 6u));
        r_ema = mean_correlation(my, qy, moment3(b + MOMENTS_EMA), moment3(b + MOMENTS_EMA + 3u), moment3(b + MOMENTS_EMA + 6u));
    }
    if mode == 6u {
        let b = cell_index(pos) * MOMENTS_PER_CELL;
        let qy = moment3(b + 3u);
        r_cur = mean_relative_error(qy, moment3(b + MOMENTS_CUR + 3u), moment3(b + MOMENTS_CUR + 6u));
        r_ema = mean_relative_error(qy, moment3(b + MOMENTS_EMA + 3u), moment3(b + MOMENTS_EMA + 6u));
    }
    if mode == 7u {
        let b = cell_index(pos) * MOMENTS_PER_CELL;
        r_cur = scale_mismatch(moment3(b + MOMENTS_CUR + 3u), moment3(b + MOMENTS_CUR + 6u));
        r_ema = scale_mismatch(moment3(b + MOMENTS_EMA + 3u), moment3(b + MOMENTS_EMA + 6u));
    }
    if mode == 4u {
        let warm = counters.grid_updates >= hyper.warmup;
        answers[qi] = vec4<f32>(r_cur, r_ema, high_lr_weight(2u, counters.grid_updates, r_cur, r_ema), select(0.0, 1.0, warm));
        return;
    }
    var sigma = high_lr_weight(mode, counters.grid_updates, r_cur, r_ema);
    if mode == 5u {
        sigma = call.fixed_sigma;
    }
    answers[qi] = vec4<f32>(max((1.0 - sigma) * f_ema + sigma * f_cur, vec3<f32>(0.0)), sigma);
}

// Which predictors a network mode (not 4) evaluates: EMA (net 1) unless High-LR only, High-LR
// (net 0) unless EMA only. The tiled and register-form passes run `first_net` first and, with
// `both`, High-LR second.
struct Predictors {
    need_ema: bool,
    need_cur: bool,
    both: bool,
    first_net: u32,
}

fn predictors(mode: u32) -> Predictors {
    let need_ema = mode != 1u;
    let need_cur = mode != 0u;
    return Predictors(need_ema, need_cur, need_ema && need_cur, select(0u, 1u, need_ema));
}

// write_answer from the first predictor's output f1 and, with `both`, the second's f2.
fn write_predictions(qi: u32, pos: vec3<f32>, mode: u32, pr: Predictors, f1: vec3<f32>, f2: vec3<f32>) {
    let f_ema = select(vec3<f32>(0.0), f1, pr.need_ema);
    let f_cur = select(f1, f2, pr.both);
    write_answer(qi, pos, mode, f_ema, select(vec3<f32>(0.0), f_cur, pr.need_cur));
}
