// The bindings of reliability_accumulate.wgsl (shader-derived layout), a module so that reliability.wgsl and
// fixed_sum.wgsl read them.

import package::nirc::types::{Call, CountersAtomic, Hyper, ReliabilitySample};

@group(0) @binding(0) var<storage, read> call: Call;
@group(0) @binding(1) var<storage, read> hyper: Hyper;
@group(0) @binding(2) var<storage, read> samples: array<ReliabilitySample>;
@group(0) @binding(3) var<storage, read_write> accum: array<atomic<u32>>;
@group(0) @binding(4) var<storage, read_write> counters: CountersAtomic;
// Per sample: its cell, and the next link of the cell's list (reliability_walk.wgsl).
@group(0) @binding(5) var<storage, read_write> sample_cells: array<vec2<u32>>;
