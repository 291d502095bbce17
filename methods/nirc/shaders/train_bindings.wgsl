// Bindings of a training pass (train_tile.wgsl, and train_forward_backward.wgsl for networks
// the tiled pass does not take).

import package::nirc::types::{Call, CountersAtomic, Hyper, ReliabilitySample, TrainingRecord};

@group(0) @binding(0) var<storage, read> call: Call;
@group(0) @binding(1) var<storage, read> hyper: Hyper;
@group(0) @binding(2) var<storage, read> records: array<TrainingRecord>;
@group(0) @binding(3) var<storage, read> params: array<f32>;
@group(0) @binding(4) var<storage, read> ema: array<f32>;
// Per record SCRATCH_STRIDE floats (a whole number of quads), as quads: the tiled pass loads and
// stores whole quads (on lavapipe each storage access is a loop over the SIMD lanes, whatever
// its width); single values go through scratch_get and scratch_set.
@group(0) @binding(5) var<storage, read_write> scratch: array<vec4<f32>>;
@group(0) @binding(6) var<storage, read_write> accum: array<atomic<u32>>;
@group(0) @binding(7) var<storage, read_write> samples: array<ReliabilitySample>;
@group(0) @binding(8) var<storage, read_write> losses: array<f32>;
@group(0) @binding(9) var<storage, read_write> counters: CountersAtomic;

fn scratch_get(i: u32) -> f32 {
    return scratch[i / 4u][i % 4u];
}
fn scratch_set(i: u32, v: f32) {
    scratch[i / 4u][i % 4u] = v;
}
