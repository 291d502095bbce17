// Bindings of an inference pass (infer_tile.wgsl, and infer.wgsl for networks the tiled pass
// does not take).

import package::nirc::types::{CacheQuery, Call, Counters, Hyper};

@group(0) @binding(0) var<storage, read> call: Call;
@group(0) @binding(1) var<storage, read> hyper: Hyper;
@group(0) @binding(2) var<storage, read> queries: array<CacheQuery>;
@group(0) @binding(3) var<storage, read> params: array<f32>;
@group(0) @binding(4) var<storage, read> ema: array<f32>;
@group(0) @binding(5) var<storage, read> moments: array<f32>;
@group(0) @binding(6) var<storage, read> counters: Counters;
@group(0) @binding(7) var<storage, read_write> answers: array<vec4<f32>>;
