// Bindings of a training pass (train_tile.wgsl, and train_forward_backward.wgsl for networks
// the tiled pass does not take).

import package::nirc::types::{Call, CountersAtomic, Hyper, ReliabilitySample, TrainingRecord};

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
