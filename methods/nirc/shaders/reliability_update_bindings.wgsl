// The bindings of reliability_update.wgsl (shader-derived layout), a module so that reliability.wgsl and
// fixed_sum.wgsl read them.

import package::nirc::types::{CountersAtomic, Hyper};

@group(0) @binding(1) var<storage, read> hyper: Hyper;
@group(0) @binding(2) var<storage, read> accum: array<u32>;
@group(0) @binding(3) var<storage, read_write> moments: array<f32>;
@group(0) @binding(4) var<storage, read_write> counters: CountersAtomic;
