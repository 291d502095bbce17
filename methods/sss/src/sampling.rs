//! The pass's per-sample math in f32, the twin of shaders/sampling.wgsl: a per-pixel
//! Cranley-Patterson offset of the R2 sequence (the thesis's online sequence, Sec. 5.1.2), the
//! sampled radius (analytic inverse eq. 5.4 or fast inverse eq. 5.6) and the per-channel weight.

/// R2's increments 1/φ2 and 1/φ2² (φ2 the plastic number).
pub const R2: [f32; 2] = [0.754_877_7, 0.569_840_3];
pub const FAST_INVERSE_C: f32 = super::inverse::FAST_INVERSE_C as f32;

/// PCG hash (Jarzynski and Olano 2020).
pub fn pcg_hash(v: u32) -> u32 {
    let state = v.wrapping_mul(747_796_405).wrapping_add(2_891_336_453);
    let word = ((state >> ((state >> 28) + 4)) ^ state).wrapping_mul(277_803_737);
    (word >> 22) ^ word
}

fn unit(h: u32) -> f32 {
    (h >> 8) as f32 * (1.0 / 16_777_216.0)
}

/// The pixel's offset of the R2 sequence this frame, from (seed, frame, pixel).
pub fn pixel_offset(seed: u32, frame: u32, pixel: u32) -> [f32; 2] {
    let h1 = pcg_hash(pixel ^ pcg_hash(frame ^ pcg_hash(seed)));
    let h2 = pcg_hash(h1);
    [unit(h1), unit(h2)]
}

fn fract(x: f32) -> f32 {
    x - x.floor()
}

/// The j-th point of the pixel's shifted R2 sequence.
pub fn r2_point(offset: [f32; 2], j: u32) -> [f32; 2] {
    let jf = j as f32;
    [fract(offset[0] + jf * R2[0]), fract(offset[1] + jf * R2[1])]
}

/// r with cdf(r) = u for shape d: eq. 5.4 (Golubev, on 1 − u) or the fast g(u) of eq. 5.6.
pub fn sample_radius(u: f32, d: f32, fast: bool) -> f32 {
    if fast {
        return d * ((2.0 - FAST_INVERSE_C) * u - 2.0) * (1.0 - u).ln();
    }
    let xi = 1.0 - u;
    let g = 1.0 + 4.0 * xi * (2.0 * xi + (1.0 + 4.0 * xi * xi).sqrt());
    3.0 * d * ((1.0 + g.powf(-1.0 / 3.0) + g.powf(1.0 / 3.0)) / (4.0 * xi)).ln()
}

/// (e^{-r/d} + e^{-r/(3d)}) / (4d).
pub fn radial_pdf(r: f32, d: f32) -> f32 {
    ((-r / d).exp() + (-r / (3.0 * d)).exp()) / (4.0 * d)
}

/// Rec. 709 luminance: what the history monitors.
pub fn luminance(c: [f32; 3]) -> f32 {
    0.2126 * c[0] + 0.7152 * c[1] + 0.0722 * c[2]
}
