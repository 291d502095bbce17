// The SSS pass's per-sample math (twin of src/sampling.rs): R2 points shifted per
// pixel, Burley radii (analytic inverse eq. 5.4 or fast inverse eq. 5.6), the radial density.

import package::pt_sampling::pcg_hash;

const R2_A: f32 = 0.7548777;
const R2_B: f32 = 0.5698403;
const FAST_INVERSE_C: f32 = 2.5715;

fn sss_unit(h: u32) -> f32 {
    return f32(h >> 8u) * (1.0 / 16777216.0);
}

fn sss_pixel_offset(seed: u32, frame: u32, pixel: u32) -> vec2f {
    let h1 = pcg_hash(pixel ^ pcg_hash(frame ^ pcg_hash(seed)));
    let h2 = pcg_hash(h1);
    return vec2f(sss_unit(h1), sss_unit(h2));
}

fn sss_r2_point(offset: vec2f, j: u32) -> vec2f {
    let jf = f32(j);
    let p = offset + vec2f(jf * R2_A, jf * R2_B);
    return p - floor(p);
}

fn sss_sample_radius(u: f32, d: f32, fast: bool) -> f32 {
    if fast {
        return d * ((2.0 - FAST_INVERSE_C) * u - 2.0) * log(1.0 - u);
    }
    let xi = 1.0 - u;
    let g = 1.0 + 4.0 * xi * (2.0 * xi + sqrt(1.0 + 4.0 * xi * xi));
    return 3.0 * d * log((1.0 + pow(g, -1.0 / 3.0) + pow(g, 1.0 / 3.0)) / (4.0 * xi));
}

fn sss_radial_pdf(r: f32, d: f32) -> f32 {
    return (exp(-r / d) + exp(-r / (3.0 * d))) / (4.0 * d);
}

fn sss_luminance(c: vec3f) -> f32 {
    return dot(c, vec3f(0.2126, 0.7152, 0.0722));
}
