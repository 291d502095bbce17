// Runs tc_decide on a batch of cases (termination::gpu_decision, the GPU-vs-CPU test).
// A case is 6 vec4f: rule (kind, relative, param, margin),
// (bias_clamp, survival, -, -), state (throughput2, path_variance, threshold, spread_sqrt),
// (spread0, vertex, -, -), stats (radiance, variance, continuation2, bias2),
// (deferred_bias2, first record filled (1/0), -, -). Output: (alpha, path variance, threshold, -).

import package::termination::decision::{TcLocalStats, TcPathState, TcRule, tc_decide, tc_threshold};

@group(0) @binding(0) var<storage, read> cases: array<vec4f>;
@group(0) @binding(1) var<storage, read_write> decisions: array<vec4f>;

@compute @workgroup_size(64, 1, 1)
fn tc_decide_probe(@builtin(global_invocation_id) id: vec3u) {
    let i = id.x;
    if 6u * i + 5u >= arrayLength(&cases) {
        return;
    }
    let c = 6u * i;
    let rule = TcRule(bitcast<u32>(cases[c].x), bitcast<u32>(cases[c].y), cases[c].z, cases[c].w, cases[c + 1u].x, cases[c + 1u].y);
    var state = TcPathState(cases[c + 2u].x, cases[c + 2u].y, cases[c + 2u].z, cases[c + 2u].w, cases[c + 3u].x, bitcast<u32>(cases[c + 3u].y));
    let stats = TcLocalStats(cases[c + 4u].x, cases[c + 4u].y, cases[c + 4u].z, cases[c + 4u].w, cases[c + 5u].x);
    let alpha = tc_decide(rule, &state, stats);
    let threshold = tc_threshold(rule, cases[c + 4u].x, cases[c + 5u].y > 0.5);
    decisions[i] = vec4f(alpha, state.path_variance, threshold, 0.0);
}
