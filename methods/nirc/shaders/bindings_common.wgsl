// Helpers shared by every NIRC pass. The sizes (IN_DIMS, WIDTH, HIDDEN, LEVELS, FEATURES,
// MLP_PARAMS, ...) and level tables are generated as package::nirc::config, the structs declared
// once for Rust and WGSL (Hyper, Call, TrainingRecord, CacheQuery, ReliabilitySample, Counters,
// CountersAtomic: gpu/mod.rs, records.rs, cpu/optimizer.rs) as package::nirc::types
// (src/gpu/shaders.rs).

import package::nirc::types::{Hyper};

// A value whose exponent bits are all ones is an Inf or a NaN. Checked on the bits because
// shader compilers may assume floats are finite.
fn is_finite(x: f32) -> bool {
    return (bitcast<u32>(x) & 0x7f800000u) != 0x7f800000u;
}

// is_finite of every component.
fn is_finite4(x: vec4<f32>) -> bool {
    return all((bitcast<vec4<u32>>(x) & vec4<u32>(0x7f800000u)) != vec4<u32>(0x7f800000u));
}

fn normalize_to_bounds(hyper: Hyper, p: vec3<f32>) -> vec3<f32> {
    return clamp((p - hyper.bounds_min.xyz) * hyper.inv_extent.xyz, vec3<f32>(0.0), vec3<f32>(1.0));
}

fn spatial_hash(v: vec3<u32>) -> u32 {
    return v.x ^ (v.y * 2654435761u) ^ (v.z * 805459861u);
}
