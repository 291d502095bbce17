// The screen-space SSS pass (render::sss::gpu; CPU twin render/src/sss/screen_pass.rs): one
// invocation per pixel picks its count with SPVG, takes that many Burley samples of the
// demodulated diffuse irradiance, and writes the scattered value and its histories.

import package::sss_types::SssParams;
import package::sss::sampling::{sss_pixel_offset, sss_r2_point, sss_sample_radius, sss_radial_pdf, sss_luminance};
import package::sss::mip::sss_mip_level;
import package::sss::spvg::{SpvgParams, spvg_state, spvg_sample_count, spvg_update, cv_update, cv_coefficient};
import package::kernel::{outside_image};

@group(0) @binding(0) var<storage, read> params: SssParams;
@group(0) @binding(1) var<storage, read> irradiance: array<vec4f>;
@group(0) @binding(2) var<storage, read> history_in: array<vec4f>;
@group(0) @binding(3) var<storage, read> cv_in: array<vec4f>;
@group(0) @binding(4) var<storage, read_write> scattered: array<vec4f>;
@group(0) @binding(5) var<storage, read_write> history_out: array<vec4f>;
@group(0) @binding(6) var<storage, read_write> cv_out: array<vec4f>;
@group(0) @binding(7) var<storage, read> mips: array<vec4f>;

// A texel of the irradiance (from_mips false) or of the MIP chain at `base` (a level of `size`
// texels), clamped to the image; texels without SSS read as the centre.
fn texel(from_mips: bool, base: u32, size: vec2u, i: i32, j: i32, centre: vec3f) -> vec3f {
    let x = clamp(i, 0, i32(size.x) - 1);
    let y = clamp(j, 0, i32(size.y) - 1);
    let index = base + u32(y) * size.x + u32(x);
    var t: vec4f;
    if from_mips {
        t = mips[index];
    } else {
        t = irradiance[index];
    }
    if t.w > 0.0 {
        return t.xyz;
    }
    return centre;
}

// Bilinear at p (texel units of that image, texel centres at +0.5).
fn bilinear(from_mips: bool, base: u32, size: vec2u, p: vec2f, centre: vec3f) -> vec3f {
    let s = p - vec2f(0.5);
    let s0 = floor(s);
    let f = s - s0;
    // Clamp before the cast: radii in the far tail are huge.
    let c = clamp(s0, vec2f(-2.0), vec2f(f32(size.x) + 1.0, f32(size.y) + 1.0));
    let i = i32(c.x);
    let j = i32(c.y);
    let a = texel(from_mips, base, size, i, j, centre);
    let b = texel(from_mips, base, size, i + 1, j, centre);
    let cc = texel(from_mips, base, size, i, j + 1, centre);
    let d = texel(from_mips, base, size, i + 1, j + 1, centre);
    return (1.0 - f.y) * ((1.0 - f.x) * a + f.x * b) + f.y * ((1.0 - f.x) * cc + f.x * d);
}

// The irradiance at q (pixels), bilinear.
fn fetch(q: vec2f, centre: vec3f) -> vec3f {
    return bilinear(false, 0u, vec2u(params.width, params.height), q, centre);
}

// Level k of the MIP chain, bilinear at q (level-0 pixels).
fn fetch_level(k: u32, q: vec2f, centre: vec3f) -> vec3f {
    let level = params.mip[k];
    return bilinear(true, level.x, level.yz, q / f32(1u << k), centre);
}

// Trilinear between levels floor(l) and floor(l) + 1 (Algorithm 2's tex2Dlod).
fn fetch_lod(l: f32, q: vec2f, centre: vec3f) -> vec3f {
    let k0 = u32(floor(l));
    let f = l - f32(k0);
    let a = fetch_level(k0, q, centre);
    if f <= 0.0 {
        return a;
    }
    return a + f * (fetch_level(min(k0 + 1u, params.mip_levels - 1u), q, centre) - a);
}

@compute @workgroup_size(8, 8, 1)
fn sss_scatter(@builtin(global_invocation_id) id: vec3u) {
    if outside_image(id, params.width, params.height) {
        return;
    }
    let pixel = id.y * params.width + id.x;
    let t = irradiance[pixel];
    if t.w <= 0.0 {
        scattered[pixel] = vec4f(t.xyz, 0.0);
        history_out[pixel] = vec4f(0.0);
        cv_out[pixel] = vec4f(0.0);
        return;
    }
    let sp = SpvgParams(params.alpha0, params.kappa, params.sigma0_sq, params.n_min, params.n_max);
    let st = spvg_state(history_in[pixel], sp);
    var n = params.fixed_count;
    if params.variant != 0u {
        n = spvg_sample_count(st, sp);
    }
    // w: pixels per unit of d here (the SSS pixel's depth sets it).
    let ds = params.d_px.w * t.w;
    let dc = params.d_px.xyz * t.w;
    let offset = sss_pixel_offset(params.seed, params.frame, pixel);
    let centre_pos = vec2f(f32(id.x) + 0.5, f32(id.y) + 0.5);
    var sum = vec3f(0.0);
    // n <= n_max (or the fixed count) <= 4096, checked on the host: a bounded loop.
    for (var j = 0u; j < n; j++) {
        let u = sss_r2_point(offset, j);
        let r = sss_sample_radius(u.x, ds, params.fast_inverse != 0u);
        let phi = 6.2831855 * u.y;
        let q = centre_pos + r * vec2f(cos(phi), sin(phi));
        let ps = sss_radial_pdf(r, ds);
        var l: vec3f;
        if params.mip_levels > 0u {
            l = fetch_lod(sss_mip_level(r, ps, n, params.mip_a, params.mip_levels), q, t.xyz);
        } else {
            l = fetch(q, t.xyz);
        }
        let w = vec3f(sss_radial_pdf(r, dc.x), sss_radial_pdf(r, dc.y), sss_radial_pdf(r, dc.z)) / ps;
        sum += l * w;
    }
    let rgb = sum / f32(n);
    let f = sss_luminance(rgb);
    let g = sss_luminance(t.xyz);
    var a = 0.0;
    if params.variant == 2u && st.valid {
        a = cv_coefficient(cv_in[pixel], params.eps_a, params.a0, f, g);
    } else if params.variant == 2u || params.variant == 3u {
        a = 1.0;
    }
    history_out[pixel] = spvg_update(st, sp, f - a * g, n);
    if st.valid {
        cv_out[pixel] = cv_update(cv_in[pixel], params.a_cv, f, g);
    } else {
        cv_out[pixel] = vec4f(f, g, 0.0, 0.0);
    }
    scattered[pixel] = vec4f(rgb, f32(n));
}
