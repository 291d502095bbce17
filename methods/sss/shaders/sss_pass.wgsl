// The screen-space SSS pass (sss::gpu; CPU twin src/screen_pass.rs): one
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
@group(0) @binding(8) var<storage, read> motion: array<vec2f>;
// The hybrid pass's technique per 8x8 tile (1: AFIS); read only when params.hybrid != 0.
@group(0) @binding(9) var<storage, read> tiles: array<u32>;

// The previous frame's histories for pixel `id` (render's reproject.rs): point-sampled at
// id + ½ + motion (the TAA resolve's convention); C_s = 0 (eqs. 4.11-4.12: an invalid history,
// w = 0) off screen, without an SSS history there, or where the depth it was written at
// (h.w = 1 + w, depth = focal/w) differs from this pixel's by more than the tolerance.
struct Reprojected {
    h: vec4f,
    j: vec4f,
}

fn reprojected(id: vec2u, w: f32) -> Reprojected {
    let none = Reprojected(vec4f(0.0), vec4f(0.0));
    let pos = vec2f(id) + 0.5 + motion[id.y * params.width + id.x];
    if !(pos.x >= 0.0 && pos.y >= 0.0 && pos.x < f32(params.width) && pos.y < f32(params.height)) {
        return none;
    }
    let q = vec2u(pos);
    let i = q.y * params.width + q.x;
    let h = history_in[i];
    if h.w <= 0.5 {
        return none;
    }
    let w_prev = h.w - 1.0;
    if w_prev > 0.0 && abs(w_prev - w) > params.depth_tolerance * w_prev {
        return none;
    }
    return Reprojected(h, cv_in[i]);
}

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

// ΔD of eq. 7.1 in pixels at the centre: depth = focal/w, scaled by the centre's w.
fn depth_difference_px(centre_w: f32, w: f32) -> f32 {
    if params.focal_px > 0.0 {
        return params.focal_px * (centre_w / w - 1.0);
    }
    return 0.0;
}

// Eq. 7.1's sums for one sample at q, radius r: over the bilinear taps that are SSS texels,
// w = bilinear weight × pdf_c(r')/pdf_s(r), r' = √(r² + ΔD²); texels off the mask weigh nothing.
struct Sums {
    num: vec3f,
    den: vec3f,
}

fn bilateral_sample(q: vec2f, r: f32, pdf_s: f32, centre_w: f32, dc: vec3f, sums: ptr<function, Sums>) {
    let size = vec2i(i32(params.width), i32(params.height));
    let s = q - vec2f(0.5);
    let s0 = floor(s);
    let f = s - s0;
    // Clamp before the cast: radii in the far tail are huge.
    let c = clamp(s0, vec2f(-2.0), vec2f(f32(params.width) + 1.0, f32(params.height) + 1.0));
    let base = vec2i(i32(c.x), i32(c.y));
    for (var k = 0u; k < 4u; k++) {
        let dx = i32(k & 1u);
        let dy = i32(k >> 1u);
        var b = select(1.0 - f.x, f.x, dx == 1) * select(1.0 - f.y, f.y, dy == 1);
        let ij = clamp(base + vec2i(dx, dy), vec2i(0), size - vec2i(1));
        let t = irradiance[u32(ij.y) * params.width + u32(ij.x)];
        if t.w <= 0.0 || b <= 0.0 {
            continue;
        }
        let dz = depth_difference_px(centre_w, t.w);
        let rp = sqrt(r * r + dz * dz);
        let w = b * vec3f(sss_radial_pdf(rp, dc.x), sss_radial_pdf(rp, dc.y), sss_radial_pdf(rp, dc.z)) / pdf_s;
        (*sums).num += w * t.xyz;
        (*sums).den += w;
    }
}

fn split_cdf(r: f32, d: f32) -> f32 {
    return 1.0 - 0.25 * exp(-r / d) - 0.75 * exp(-r / (3.0 * d));
}

// The monitored luminance's encoding Y^(1/γ_m) (1: linear).
fn encode(y: f32) -> f32 {
    if params.monitor_gamma == 1.0 {
        return y;
    }
    return pow(max(y, 0.0), 1.0 / params.monitor_gamma);
}

@compute @workgroup_size(8, 8, 1)
fn sss_scatter(@builtin(global_invocation_id) id: vec3u, @builtin(workgroup_id) tile: vec3u) {
    if outside_image(id, params.width, params.height) {
        return;
    }
    let pixel = id.y * params.width + id.x;
    // P1 of the hybrid: AFIS tiles only; a separable pixel keeps no history.
    if params.hybrid != 0u && tiles[tile.y * ((params.width + 7u) / 8u) + tile.x] != 1u {
        history_out[pixel] = vec4f(0.0);
        cv_out[pixel] = vec4f(0.0);
        return;
    }
    let t = irradiance[pixel];
    if t.w <= 0.0 {
        scattered[pixel] = vec4f(t.xyz, 0.0);
        history_out[pixel] = vec4f(0.0);
        cv_out[pixel] = vec4f(0.0);
        return;
    }
    // w: pixels per unit of d here (the SSS pixel's depth sets it).
    let ds = params.d_px.w * t.w;
    let dc = params.d_px.xyz * t.w;
    // The direct/distant split (render's split.rs): r0 = √2/2 px, γ per channel, u from cdf(r0).
    var u0 = 0.0;
    var gamma = vec3f(1.0);
    var gamma_s = 1.0;
    if params.split != 0u {
        let r0 = 0.70710677;
        u0 = split_cdf(r0, ds);
        if params.gamma >= 0.0 {
            gamma = vec3f(params.gamma);
            gamma_s = params.gamma;
        } else {
            gamma = vec3f(1.0 - split_cdf(r0, dc.x), 1.0 - split_cdf(r0, dc.y), 1.0 - split_cdf(r0, dc.z));
            gamma_s = 1.0 - u0;
        }
        // Algorithm 3, lines 1-2: no distant samples, nothing to track.
        if gamma_s < params.eps_u {
            scattered[pixel] = vec4f((vec3f(1.0) - gamma) * t.xyz, 0.0);
            history_out[pixel] = vec4f(0.0);
            cv_out[pixel] = vec4f(0.0);
            return;
        }
    }
    let sp = SpvgParams(params.alpha0, params.kappa, params.sigma0_sq, params.n_min, params.n_max);
    let prev = reprojected(id.xy, t.w);
    let st = spvg_state(prev.h, sp);
    // n_hat: SPVG's count (eq. 4.9), kept in the history; n: the distant samples taken
    // (Algorithm 3: n_hat; eq. 5.20: max(1, floor(n_hat γ + ½))).
    var n = params.fixed_count;
    var n_hat = n;
    if params.variant != 0u {
        n_hat = spvg_sample_count(st, sp);
        n = n_hat;
        if params.gamma_scaled != 0u {
            n = max(1u, u32(floor(f32(n_hat) * gamma_s + 0.5)));
        }
    }
    let offset = sss_pixel_offset(params.seed, params.frame, pixel);
    let centre_pos = vec2f(f32(id.x) + 0.5, f32(id.y) + 0.5);
    var sums = Sums(vec3f(0.0), vec3f(0.0));
    // n <= n_max (or the fixed count) <= 4096, checked on the host: a bounded loop.
    for (var j = 0u; j < n; j++) {
        let u = sss_r2_point(offset, j);
        let r = sss_sample_radius((1.0 - u.x) * u0 + u.x, ds, params.fast_inverse != 0u);
        let phi = 6.2831855 * u.y;
        let q = centre_pos + r * vec2f(cos(phi), sin(phi));
        let ps = sss_radial_pdf(r, ds);
        if params.mip_levels > 0u {
            let l = fetch_lod(sss_mip_level(r, ps, n, params.mip_a, params.mip_levels), q, t.xyz);
            let w = vec3f(sss_radial_pdf(r, dc.x), sss_radial_pdf(r, dc.y), sss_radial_pdf(r, dc.z)) / ps;
            sums.num += w * l;
            sums.den += w;
        } else {
            bilateral_sample(q, r, ps, t.w, dc, &sums);
        }
    }
    var ls = t.xyz;
    if n > 0u {
        ls = select(t.xyz, sums.num / max(sums.den, vec3f(1e-30)), sums.den > vec3f(0.0));
    }
    var distant = vec3f(0.0);
    if n > 0u {
        distant = gamma * ls;
    }
    let rgb = (vec3f(1.0) - gamma) * t.xyz + distant;
    // f̄ = L_o − (1 − γ)B (eq. 6.22), ḡ = γB (eq. 6.14), luminance, encoded.
    let f = encode(sss_luminance(distant));
    let g = encode(sss_luminance(gamma * t.xyz));
    var a = 0.0;
    if params.variant == 2u && st.valid {
        a = cv_coefficient(prev.j, params.eps_a, params.a0, f, g);
    } else if params.variant == 2u || params.variant == 3u {
        a = 1.0;
    }
    history_out[pixel] = spvg_update(st, sp, f - a * g, n_hat) + vec4f(0.0, 0.0, 0.0, t.w);
    if st.valid {
        cv_out[pixel] = cv_update(prev.j, params.a_cv, f, g);
    } else {
        cv_out[pixel] = vec4f(f, g, 0.0, 0.0);
    }
    scattered[pixel] = vec4f(rgb, f32(n));
}
