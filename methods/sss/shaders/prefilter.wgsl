// The irradiance prefiltering pass (thesis Sec. 5.2 and 5.4's P2; CPU twin
// src/prefilter.rs): one dispatch per level. Level 0 is the irradiance with the SSS
// mask as its share; level k is the 2x2 mean of level k-1 over SSS texels, with their share.

import package::sss_types::SssParams;
import package::kernel::{outside_image};

struct MipLevel {
    k: u32,
    _pad0: u32,
    _pad1: u32,
    _pad2: u32,
}

@group(0) @binding(0) var<storage, read> params: SssParams;
@group(0) @binding(1) var<storage, read> irradiance: array<vec4f>;
@group(0) @binding(2) var<storage, read_write> mips: array<vec4f>;
@group(0) @binding(3) var<storage, read> mip_level: MipLevel;

@compute @workgroup_size(8, 8, 1)
fn sss_prefilter(@builtin(global_invocation_id) id: vec3u) {
    let k = mip_level.k;
    let level = params.mip[k];
    if outside_image(id, level.y, level.z) {
        return;
    }
    let out = level.x + id.y * level.y + id.x;
    if k == 0u {
        let t = irradiance[id.y * params.width + id.x];
        if t.w > 0.0 {
            mips[out] = vec4f(t.xyz, 1.0);
        } else {
            mips[out] = vec4f(0.0);
        }
        return;
    }
    let prev = params.mip[k - 1u].yz;
    let base = params.mip[k - 1u].x;
    var sum = vec3f(0.0);
    var share = 0.0;
    for (var c = 0u; c < 4u; c++) {
        let child = 2u * id.xy + vec2u(c & 1u, c >> 1u);
        if child.x < prev.x && child.y < prev.y {
            let t = mips[base + child.y * prev.x + child.x];
            sum += t.w * t.xyz;
            share += t.w;
        }
    }
    if share > 0.0 {
        mips[out] = vec4f(sum / share, 0.25 * share);
    } else {
        mips[out] = vec4f(0.0);
    }
}
