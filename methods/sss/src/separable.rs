//! The separable screen-space baseline (Jimenez et al. 2015, thesis Sec. 2.2.2.3): a horizontal
//! then a vertical 1-D pass over the demodulated diffuse irradiance with the pre-integrated
//! rank-1 kernel of eqs. 2.60-2.67, here of Burley's profile itself. Its projection has a
//! closed form: a_p(x) = ∫ R(√(x² + y²)) dy = A (K0(|x|/d) + K0(|x|/(3d))) / (4πd), which
//! integrates to A; the pass uses it divided by A (the albedo is applied after the pass).
//! Taps sit at Jimenez's quadratic offsets (separable-sss's SeparableSSS.cpp, exponent 2) and
//! weigh the kernel's mass over each tap's cell, the outermost cells taking the tails, so each
//! channel's weights sum to 1. This file is the CPU twin of shaders/separable.wgsl.

use super::frame_input::SssFrame;
use super::pixel::PixelResult;
use std::f64::consts::PI;

/// Tap offsets span ±RANGE times the widest channel's d (the kernel's mass beyond 8d is ~1%
/// per side; the outer cells take it).
pub const RANGE: f64 = 8.0;
/// The most taps per 1-D pass (the WGSL kernel buffer's size).
pub const MAX_TAPS: u32 = 63;

/// ∫_X^∞ K0(z) dz = ∫_0^∞ e^{−X cosh t} / cosh t dt (from K0(z) = ∫_0^∞ e^{−z cosh t} dt), by
/// Simpson's rule in t: the integrand is smooth, and 1/cosh t < 2e^{−t} bounds the cut tail.
pub fn k0_tail(x: f64) -> f64 {
    assert!(x >= 0.0, "k0_tail of negative {x}");
    let (t_max, n) = (40.0, 2000);
    let h = t_max / n as f64;
    let f = |t: f64| {
        let c = f64::cosh(t);
        (-x * c).exp() / c
    };
    let mut s = f(0.0) + f(t_max);
    for i in 1..n {
        s += f(i as f64 * h) * if i % 2 == 1 { 4.0 } else { 2.0 };
    }
    s * h / 3.0
}

/// The kernel's mass (divided by A) beyond |x| on one side: (tail(x/d) + 3 tail(x/(3d))) / (4π).
/// At x = 0 it is 1/2: ∫_0^∞ K0 = π/2.
pub fn one_sided_tail(x: f64, d: f64) -> f64 {
    (k0_tail(x.abs() / d) + 3.0 * k0_tail(x.abs() / (3.0 * d))) / (4.0 * PI)
}

/// The kernel's cdf: the mass of a_p/A on (−∞, x].
pub fn kernel_cdf(x: f64, d: f64) -> f64 {
    if x.is_infinite() {
        return if x > 0.0 { 1.0 } else { 0.0 };
    }
    let t = one_sided_tail(x, d);
    if x >= 0.0 { 1.0 - t } else { t }
}

/// Jimenez's tap offsets in units of the sampled d: o_i = −R + 2Ri/(n−1), offset = sign(o) o²/R.
pub fn tap_offsets(taps: u32) -> Vec<f64> {
    let step = 2.0 * RANGE / (taps - 1) as f64;
    (0..taps)
        .map(|i| {
            let o = -RANGE + i as f64 * step;
            o.signum() * o * o / RANGE
        })
        .collect()
}

/// The kernel: per tap (offset in units of d_px[widest], weight r, g, b), the weights being
/// each channel's mass over the tap's cell (from the midpoints to its neighbours; ±∞ outside).
pub fn kernel(taps: u32, d_px: [f32; 3]) -> Result<Vec<[f32; 4]>, String> {
    if taps < 3 || taps.is_multiple_of(2) || taps > MAX_TAPS {
        return Err(format!("separable SSS taps {taps}; expected an odd count in [3, {MAX_TAPS}]"));
    }
    if d_px.iter().any(|d| !(*d > 0.0)) {
        return Err(format!("separable SSS d {d_px:?}; expected positive"));
    }
    let ds = d_px[0].max(d_px[1]).max(d_px[2]) as f64;
    let o = tap_offsets(taps);
    let n = o.len();
    let edge = |i: usize| {
        if i == 0 {
            f64::NEG_INFINITY
        } else if i == n {
            f64::INFINITY
        } else {
            0.5 * (o[i - 1] + o[i])
        }
    };
    Ok((0..n)
        .map(|i| {
            let w = d_px.map(|d| {
                let d = d as f64 / ds;
                (kernel_cdf(edge(i + 1), d) - kernel_cdf(edge(i), d)) as f32
            });
            [o[i] as f32, w[0], w[1], w[2]]
        })
        .collect())
}

/// Linear fetch at position p along one axis (x when `horizontal`), texel centres at +0.5,
/// clamped to the image; texels outside the SSS mask read as the centre (no bleeding).
fn fetch_1d(
    texels: &[[f32; 4]],
    mask: &[[f32; 4]],
    width: u32,
    height: u32,
    x: u32,
    y: u32,
    p: f32,
    horizontal: bool,
    centre: [f32; 3],
) -> [f32; 3] {
    let (w, h) = (width as i32, height as i32);
    let len = if horizontal { w } else { h };
    let s = (p - 0.5).clamp(-2.0, len as f32 + 1.0);
    let s0 = s.floor();
    let f = s - s0;
    let texel = |k: i32| {
        let k = k.clamp(0, len - 1);
        let i = if horizontal { (y as i32 * w + k) as usize } else { (k * w + x as i32) as usize };
        if mask[i][3] > 0.0 { [texels[i][0], texels[i][1], texels[i][2]] } else { centre }
    };
    let (a, b) = (texel(s0 as i32), texel(s0 as i32 + 1));
    std::array::from_fn(|c| (1.0 - f) * a[c] + f * b[c])
}

/// One 1-D pass: per SSS pixel Σ_i w_i L(centre + o_i d_s w e), e the pass's axis; other
/// pixels pass through. `source` is the irradiance (first pass) or the first pass's output.
pub(crate) fn pass(
    frame: &SssFrame,
    source: &[[f32; 4]],
    kernel: &[[f32; 4]],
    horizontal: bool,
) -> Vec<[f32; 4]> {
    let ds = frame.d_sample();
    (0..frame.height)
        .flat_map(|y| (0..frame.width).map(move |x| (x, y)))
        .map(|(x, y)| {
            let i = (y * frame.width + x) as usize;
            let (t, w) = (source[i], frame.irradiance[i][3]);
            if w <= 0.0 {
                return t;
            }
            let centre = [t[0], t[1], t[2]];
            let base = if horizontal { x } else { y } as f32 + 0.5;
            let scale = ds * w;
            let mut sum = [0.0f32; 3];
            for k in kernel {
                let l = fetch_1d(
                    source,
                    &frame.irradiance,
                    frame.width,
                    frame.height,
                    x,
                    y,
                    base + k[0] * scale,
                    horizontal,
                    centre,
                );
                for c in 0..3 {
                    sum[c] += k[c + 1] * l[c];
                }
            }
            [sum[0], sum[1], sum[2], w]
        })
        .collect()
}

/// Both passes; each SSS pixel's count is the 2·taps fetches it took.
pub fn step(frame: &SssFrame, kernel: &[[f32; 4]]) -> Vec<PixelResult> {
    let horizontal = pass(frame, &frame.irradiance, kernel, true);
    let both = pass(frame, &horizontal, kernel, false);
    both.iter()
        .zip(&frame.irradiance)
        .map(|(v, t)| PixelResult {
            rgb: [v[0], v[1], v[2]],
            count: if t[3] > 0.0 { 2 * kernel.len() as u32 } else { 0 },
        })
        .collect()
}
