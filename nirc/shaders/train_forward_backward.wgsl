// Training pass 1 (one thread per record): encode, forward of both predictors, relative L2
// loss, backward of the High-LR predictor. Writes the activations and pre-activation gradients
// for the weight-gradient pass, scatters the hash-grid gradients into exact fixed-point sums
// (order-independent), and the (y, f_cur, f_ema) sample for the reliability grid.

@group(0) @binding(0) var<uniform> call: Call;
@group(0) @binding(1) var<uniform> hyper: Hyper;
@group(0) @binding(2) var<storage, read> records: array<TrainingRecord>;
@group(0) @binding(3) var<storage, read> params: array<f32>;
@group(0) @binding(4) var<storage, read> ema: array<f32>;
@group(0) @binding(5) var<storage, read_write> scratch: array<f32>;
@group(0) @binding(6) var<storage, read_write> accum: array<atomic<u32>>;
@group(0) @binding(7) var<storage, read_write> samples: array<ReliabilitySample>;
@group(0) @binding(8) var<storage, read_write> losses: array<f32>;
@group(0) @binding(9) var<storage, read_write> counters: CountersAtomic;

@compute @workgroup_size(64)
fn main(@builtin(global_invocation_id) gid: vec3<u32>, @builtin(local_invocation_index) lid: u32) {
    let r = gid.x;
    let in_range = r < call.n;
    let rec = records[min(r, call.n - 1u)];
    let pos = rec.position.xyz;
    let dir = rec.direction.xyz;

    load_weights(1u, lid);
    var f_ema = vec3<f32>(0.0);
    if in_range {
        encode_input(1u, pos, dir);
        f_ema = mlp_forward(1u);
    }
    load_weights(0u, lid);
    if !in_range {
        return;
    }
    encode_input(0u, pos, dir);
    let f = mlp_forward(0u);
    let y = rec.target_rgb.xyz;

    // Relative L2, denominators under stop-gradient.
    var den: vec3<f32>;
    if hyper.loss_luminance == 1u {
        let l = 0.2126 * f.x + 0.7152 * f.y + 0.0722 * f.z;
        den = vec3<f32>(l * l + hyper.loss_epsilon);
    } else {
        den = f * f + vec3<f32>(hyper.loss_epsilon);
    }
    var loss = 0.0;
    var d_out = vec3<f32>(0.0);
    for (var c = 0u; c < 3u; c++) {
        let diff = f[c] - y[c];
        loss += diff * diff / den[c];
        d_out[c] = (2.0 / 3.0) * diff / den[c];
    }
    loss = loss / 3.0;
    losses[r] = loss;
    var ok = is_finite(loss);

    mlp_backward(d_out);
    let base = r * SCRATCH_STRIDE;
    for (var i = 0u; i < ACT_FLOATS; i++) {
        scratch[base + i] = acts[i];
    }
    for (var i = 0u; i < DELTA_FLOATS; i++) {
        scratch[base + ACT_FLOATS + i] = deltas[i];
    }

    let p = normalize_to_bounds(hyper, pos);
    for (var l = 0u; l < LEVELS; l++) {
        let corners = level_corners(l, p);
        for (var c = 0u; c < 8u; c++) {
            for (var k = 0u; k < FEATURES; k++) {
                let g = corners.weight[c] * d_input[l * FEATURES + k];
                ok = fixed_add(3u * (corners.index[c] + k - MLP_PARAMS), g) && ok;
            }
        }
    }
    if !ok {
        atomicOr(&counters.flag, 1u);
    }
    samples[r] = ReliabilitySample(rec.position, rec.target_rgb, vec4<f32>(f, 0.0), vec4<f32>(f_ema, 0.0));
}
