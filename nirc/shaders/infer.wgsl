// Inference (one thread per query): evaluates the predictors the mode needs, looks up the
// query's reliability cell and answers max(0, (1 - σ) f_EMA + σ f_cur) with σ in .w.
// Mode 4 (diagnostics, no network): (r̄_cur, r̄_EMA, σ of the blend, 1 once warmed up).

@group(0) @binding(0) var<uniform> call: Call;
@group(0) @binding(1) var<uniform> hyper: Hyper;
@group(0) @binding(2) var<storage, read> queries: array<CacheQuery>;
@group(0) @binding(3) var<storage, read> params: array<f32>;
@group(0) @binding(4) var<storage, read> ema: array<f32>;
@group(0) @binding(5) var<storage, read> moments: array<f32>;
@group(0) @binding(6) var<storage, read> counters: Counters;
@group(0) @binding(7) var<storage, read_write> answers: array<vec4<f32>>;

fn moment3(base: u32) -> vec3<f32> {
    return vec3<f32>(moments[base], moments[base + 1u], moments[base + 2u]);
}

@compute @workgroup_size(64)
fn main(@builtin(global_invocation_id) gid: vec3<u32>, @builtin(local_invocation_index) lid: u32) {
    let qi = gid.x;
    let in_range = qi < call.n;
    let q = queries[min(qi, call.n - 1u)];
    let pos = q.position.xyz;
    let dir = q.direction.xyz;
    let mode = call.mode;

    var f_ema = vec3<f32>(0.0);
    var f_cur = vec3<f32>(0.0);
    if mode != 1u && mode != 4u {
        load_weights(1u, lid);
        if in_range {
            encode_input(1u, pos, dir);
            f_ema = mlp_forward(1u);
        }
    }
    if mode != 0u && mode != 4u {
        load_weights(0u, lid);
        if in_range {
            encode_input(0u, pos, dir);
            f_cur = mlp_forward(0u);
        }
    }
    if !in_range {
        return;
    }
    var r_cur = 0.0;
    var r_ema = 0.0;
    if mode >= 2u {
        let b = cell_index(pos) * MOMENTS_PER_CELL;
        let my = moment3(b);
        let qy = moment3(b + 3u);
        r_cur = mean_correlation(my, qy, moment3(b + MOMENTS_CUR), moment3(b + MOMENTS_CUR + 3u), moment3(b + MOMENTS_CUR + 6u));
        r_ema = mean_correlation(my, qy, moment3(b + MOMENTS_EMA), moment3(b + MOMENTS_EMA + 3u), moment3(b + MOMENTS_EMA + 6u));
    }
    if mode == 4u {
        let warm = counters.grid_updates >= hyper.warmup;
        answers[qi] = vec4<f32>(r_cur, r_ema, high_lr_weight(2u, counters.grid_updates, r_cur, r_ema), select(0.0, 1.0, warm));
        return;
    }
    let sigma = high_lr_weight(mode, counters.grid_updates, r_cur, r_ema);
    let l = max((1.0 - sigma) * f_ema + sigma * f_cur, vec3<f32>(0.0));
    answers[qi] = vec4<f32>(l, sigma);
}
