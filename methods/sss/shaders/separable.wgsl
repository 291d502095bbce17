// The separable SSS baseline (sss::separable, its CPU twin; P2 and P3 of the hybrid pass,
// which skip the AFIS tiles): a horizontal pass from the
// irradiance into `intermediate`, then a vertical pass from it into `scattered`, each a sum of
// the pre-integrated Burley kernel's taps (offset in units of the widest d, weight rgb).

import package::sss_types::SssParams;
import package::kernel::{outside_image};

@group(0) @binding(0) var<storage, read> params: SssParams;
@group(0) @binding(1) var<storage, read> irradiance: array<vec4f>;
@group(0) @binding(2) var<storage, read> sss_kernel: array<vec4f>;
@group(0) @binding(3) var<storage, read_write> intermediate: array<vec4f>;
@group(0) @binding(4) var<storage, read_write> scattered: array<vec4f>;
// The hybrid pass's technique per 8x8 tile (1: AFIS, whose pixels P1 and P4 write).
@group(0) @binding(5) var<storage, read> tiles: array<u32>;

fn afis_tile(tile: vec3u) -> bool {
    return params.hybrid != 0u && tiles[tile.y * ((params.width + 7u) / 8u) + tile.x] == 1u;
}

// The texel index at position k along the pass's axis through pixel (x, y), clamped.
fn axis_index(k: i32, x: u32, y: u32, horizontal: bool) -> u32 {
    if horizontal {
        return y * params.width + u32(clamp(k, 0, i32(params.width) - 1));
    }
    return u32(clamp(k, 0, i32(params.height) - 1)) * params.width + x;
}

// Linear weights at position p along an axis of `len` texels: (first texel, fraction).
fn axis_lerp(p: f32, len: u32) -> vec2f {
    let s = clamp(p - 0.5, -2.0, f32(len) + 1.0);
    let s0 = floor(s);
    return vec2f(s0, s - s0);
}

fn source_texel(i: u32, horizontal: bool, centre: vec3f) -> vec3f {
    if irradiance[i].w <= 0.0 {
        return centre;
    }
    if horizontal {
        return irradiance[i].xyz;
    }
    return intermediate[i].xyz;
}

// One 1-D pass at pixel (x, y) over the source (irradiance when horizontal, else intermediate).
fn filter_1d(x: u32, y: u32, horizontal: bool, centre: vec3f, w: f32) -> vec3f {
    var len = params.height;
    var base = f32(y) + 0.5;
    if horizontal {
        len = params.width;
        base = f32(x) + 0.5;
    }
    let scale = params.d_px.w * w;
    var sum = vec3f(0.0);
    // taps <= 63, checked on the host: a bounded loop.
    for (var k = 0u; k < params.taps; k++) {
        let tap = sss_kernel[k];
        let l = axis_lerp(base + tap.x * scale, len);
        let a = source_texel(axis_index(i32(l.x), x, y, horizontal), horizontal, centre);
        let b = source_texel(axis_index(i32(l.x) + 1, x, y, horizontal), horizontal, centre);
        sum += tap.yzw * mix(a, b, l.y);
    }
    return sum;
}

@compute @workgroup_size(8, 8, 1)
fn sss_separable_h(@builtin(global_invocation_id) id: vec3u, @builtin(workgroup_id) tile: vec3u) {
    // An AFIS tile's buffer-one texels hold P1's result: the vertical pass's first-pass stand-in.
    if outside_image(id, params.width, params.height) || afis_tile(tile) {
        return;
    }
    let pixel = id.y * params.width + id.x;
    let t = irradiance[pixel];
    if t.w <= 0.0 {
        intermediate[pixel] = t;
        return;
    }
    intermediate[pixel] = vec4f(filter_1d(id.x, id.y, true, t.xyz, t.w), t.w);
}

@compute @workgroup_size(8, 8, 1)
fn sss_separable_v(@builtin(global_invocation_id) id: vec3u, @builtin(workgroup_id) tile: vec3u) {
    if outside_image(id, params.width, params.height) || afis_tile(tile) {
        return;
    }
    let pixel = id.y * params.width + id.x;
    let t = irradiance[pixel];
    if t.w <= 0.0 {
        scattered[pixel] = vec4f(t.xyz, 0.0);
        return;
    }
    let c = intermediate[pixel];
    scattered[pixel] = vec4f(filter_1d(id.x, id.y, false, c.xyz, t.w), f32(2u * params.taps));
}
