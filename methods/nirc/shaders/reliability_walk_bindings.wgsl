// The bindings of reliability_walk.wgsl (shader-derived layout), a module so that reliability.wgsl and
// fixed_sum.wgsl read them.

import package::nirc::types::{Call, Hyper, ReliabilitySample};

@group(0) @binding(0) var<storage, read> call: Call;
@group(0) @binding(1) var<storage, read> hyper: Hyper;
@group(0) @binding(2) var<storage, read> samples: array<ReliabilitySample>;
@group(0) @binding(3) var<storage, read_write> accum: array<u32>;
@group(0) @binding(4) var<storage, read> moments: array<f32>;
@group(0) @binding(5) var<storage, read> sample_cells: array<vec2<u32>>;
