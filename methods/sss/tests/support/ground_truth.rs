//! A path-traced ground truth for the screen-space pass on a flat subsurface plane: the
//! exitance of a homogeneous half-space (random walks of `random_walk`, isotropic phase,
//! index-matched boundary) under the frame's irradiance entering normally, per pixel, divided
//! by the walk's own albedo A (the pass's output is divided by A too). A half-space is
//! translation invariant, so the exitance at p is ∫ E(q) R_walk(p − q) dq = A·E[E(p − Δ)] with
//! Δ the exit offset of a walk entering at the origin: each walk's offset is one path sample
//! of every pixel. E between texel centres is the same clamped bilinear reconstruction the pass
//! reads, so the two differ only by the profile: Burley's against the transport itself.
//!
//! The bound the test derives (an irradiance that varies along x only, monotone, e.g. a shadow
//! edge): both results are E averaged over an offset law, so their difference is
//! ∫ e(x − δ) d(G_b − G_w)(δ) with G the law of Δx, at most osc(e)·sup|G_b − G_w|; and
//! G(δ) = ∫ P(r cos φ ≤ δ) dF(r), whose integrand is monotone in r with a range of ½, so
//! sup|G_b − G_w| ≤ ½ sup|F_b − F_w|, F the radial cdfs. Hence
//! |pass(n → ∞) − truth| ≤ osc(e)·½·D with D = sup_r |F_Burley(r) − F_walk(r)|.

use super::random_walk::{Medium, searchlight_exits};
use sss::SssFrame;
use sss::profile::cdf;

/// The clamped bilinear irradiance at p (pixels, texel centres at +0.5), channel c.
pub fn bilinear(frame: &SssFrame, p: [f64; 2], c: usize) -> f64 {
    let (w, h) = (frame.width as i64, frame.height as i64);
    let (x, y) = (p[0] - 0.5, p[1] - 0.5);
    let (x0, y0) = (x.floor(), y.floor());
    let (fx, fy) = (x - x0, y - y0);
    let texel = |i: i64, j: i64| {
        let (i, j) = (i.clamp(0, w - 1), j.clamp(0, h - 1));
        frame.irradiance[(j * w + i) as usize][c] as f64
    };
    // Clamp before the cast: offsets in the far tail are huge.
    let (i, j) = (x0.clamp(-2.0, w as f64 + 1.0) as i64, y0.clamp(-2.0, h as f64 + 1.0) as i64);
    (1.0 - fy) * ((1.0 - fx) * texel(i, j) + fx * texel(i + 1, j))
        + fy * ((1.0 - fx) * texel(i, j + 1) + fx * texel(i + 1, j + 1))
}

/// The walks of a searchlight on `medium`, in pixels of `pixel` scene units: exit offsets and
/// the albedo A (exits / walks).
pub struct WalkOffsets {
    pub offsets: Vec<[f64; 2]>,
    pub albedo: f64,
}

impl WalkOffsets {
    pub fn trace(medium: &Medium, paths: u64, seed: u64, pixel: f64) -> Self {
        let (exits, n) = searchlight_exits(medium, paths, seed);
        let albedo = exits.len() as f64 / n as f64;
        Self { offsets: exits.iter().map(|e| [e[0] / pixel, e[1] / pixel]).collect(), albedo }
    }

    /// The ground truth per pixel and channel: the mean of E(p − Δ) over the walks that left
    /// (the exitance divided by A).
    pub fn truth(&self, frame: &SssFrame) -> Vec<[f64; 3]> {
        let n = self.offsets.len().max(1) as f64;
        (0..frame.width * frame.height)
            .map(|i| {
                let p = [(i % frame.width) as f64 + 0.5, (i / frame.width) as f64 + 0.5];
                let mut sum = [0.0; 3];
                for o in &self.offsets {
                    for (c, s) in sum.iter_mut().enumerate() {
                        *s += bilinear(frame, [p[0] - o[0], p[1] - o[1]], c);
                    }
                }
                sum.map(|s| s / n)
            })
            .collect()
    }

    /// D = sup_r |F_Burley(r; d) − F_walk(r)| over the walks' empirical radial cdf (pixels).
    pub fn cdf_gap(&self, d_px: f64) -> f64 {
        let mut r: Vec<f64> = self.offsets.iter().map(|o| o[0].hypot(o[1])).collect();
        r.sort_by(f64::total_cmp);
        let n = r.len() as f64;
        r.iter()
            .enumerate()
            .map(|(k, &r)| {
                let f = cdf(r, d_px);
                (f - k as f64 / n).abs().max((f - (k + 1) as f64 / n).abs())
            })
            .fold(0.0, f64::max)
    }
}

/// The Dvoretzky-Kiefer-Wolfowitz margin: an empirical cdf of n draws is within it of the
/// true cdf everywhere with probability 1 − δ.
pub fn dkw_margin(n: usize, delta: f64) -> f64 {
    ((2.0 / delta).ln() / (2.0 * n as f64)).sqrt()
}

/// Hoeffding's margin for the mean of n independent values in a range of `range`.
pub fn hoeffding_margin(n: usize, range: f64, delta: f64) -> f64 {
    range * ((2.0 / delta).ln() / (2.0 * n as f64)).sqrt()
}
