// Types shared by every NIRC pass. The Rust side prepends the sizes as constants (IN_DIMS,
// WIDTH, HIDDEN, LEVELS, FEATURES, MLP_PARAMS, ...) and appends the level tables.

// Settings that do not change during a cache's life (see gpu/mod.rs `Hyper`).
struct Hyper {
    bounds_min: vec4<f32>,
    inv_extent: vec4<f32>,
    learning_rate: f32,
    beta1: f32,
    beta2: f32,
    adam_epsilon: f32,
    alpha: f32,
    loss_epsilon: f32,
    lambda: f32,
    reliability_epsilon: f32,
    kappa: f32,
    warmup: u32,
    reliability_resolution: u32,
    loss_luminance: u32,
    // 1: the moments move once per sample (the paper), 0: once per step towards the batch mean.
    moments_per_sample: u32,
    pad0: u32,
    pad1: u32,
    pad2: u32,
}

// What one train/infer call works on.
struct Call {
    n: u32,
    inv_n: f32,
    mode: u32,
    num_chunks: u32,
    // σ of the fixed blend (mode 5).
    fixed_sigma: f32,
    pad0: u32,
    pad1: u32,
    pad2: u32,
}

struct TrainingRecord {
    position: vec4<f32>,
    direction: vec4<f32>,
    target_rgb: vec4<f32>,
}

struct CacheQuery {
    position: vec4<f32>,
    direction: vec4<f32>,
}

struct ReliabilitySample {
    position: vec4<f32>,
    target_rgb: vec4<f32>,
    f_cur: vec4<f32>,
    f_ema: vec4<f32>,
}

// A value whose exponent bits are all ones is an Inf or a NaN. Checked on the bits because
// shader compilers may assume floats are finite.
fn is_finite(x: f32) -> bool {
    return (bitcast<u32>(x) & 0x7f800000u) != 0x7f800000u;
}

fn normalize_to_bounds(hyper: Hyper, p: vec3<f32>) -> vec3<f32> {
    return clamp((p - hyper.bounds_min.xyz) * hyper.inv_extent.xyz, vec3<f32>(0.0), vec3<f32>(1.0));
}

fn spatial_hash(v: vec3<u32>) -> u32 {
    return v.x ^ (v.y * 2654435761u) ^ (v.z * 805459861u);
}
