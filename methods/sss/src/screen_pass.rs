//! The screen-space SSS pass on the CPU (the reference the WGSL pass is tested against, and the
//! test bed of SPVG and the control variates): per SSS pixel, SPVG picks the count n, n Burley
//! samples of the demodulated diffuse irradiance around the pixel give the scattered value
//! (eq. 5.2, divided by A: the albedo is applied after the pass), and the histories update.

use super::control_variates::EmCovariance;
use super::frame_input::SssFrame;
use super::hybrid::{self, Hybrid};
use super::pixel::{PixelHistory, PixelResult};
use super::prefilter::{self, MipChain, Prefilter};
use super::reproject;
use super::sampling::{luminance, pixel_offset, r2_point, radial_pdf, sample_radius};
use super::separable;
use super::split::{self, DistantCount, Split};
use super::spvg::{self, SpvgSettings};
use serde::{Deserialize, Serialize};

/// How the count is chosen and what the history monitors.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
pub enum SssVariant {
    /// n = count everywhere (the thesis's fixed-64 baseline; 2048 for its reference).
    Fixed { count: u32 },
    /// AS: SPVG on the scattered luminance.
    Adaptive,
    /// AS + OCV: SPVG on the residual f̄ − a_t G(t) with a_t from the EMC (eq. 6.21).
    OnlineCv,
    /// AS + CCV: SPVG on f̄ − G(t) (a = 1, Sec. 6.6).
    ConstantCv,
    /// The separable baseline (Jimenez et al. 2015): two 1-D passes of `taps` taps each with
    /// Burley's pre-integrated kernel (`separable`); no history.
    Separable { taps: u32 },
}

impl SssVariant {
    pub fn code(&self) -> u32 {
        match self {
            SssVariant::Fixed { .. } => 0,
            SssVariant::Adaptive => 1,
            SssVariant::OnlineCv => 2,
            SssVariant::ConstantCv => 3,
            SssVariant::Separable { .. } => 4,
        }
    }
}

/// The pass's settings.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SssPassSettings {
    pub variant: SssVariant,
    pub spvg: SpvgSettings,
    /// Sample radii with g(ξ) of eq. 5.6 instead of the analytic inverse.
    pub fast_inverse: bool,
    /// ε_a, a0 and the CV history's exponential weight a_cv (Sec. 6.5, 7.3).
    pub eps_a: f32,
    pub a0: f32,
    pub a_cv: f32,
    pub seed: u32,
    /// AFIS (Sec. 5.2): samples read a prefiltered MIP chain at eq. 5.12's level; None reads
    /// the irradiance itself (level 0). The Monte Carlo variants only.
    pub prefilter: Option<Prefilter>,
    /// The direct/distant split (Sec. 5.3.1); None samples the whole disc (γ = 1, r0 = 0).
    pub split: Option<Split>,
    /// The monitored luminance's encoding Y^(1/γ_m) (Sec. 4.4: gamma-corrected; 1 = linear).
    pub monitor_gamma: f32,
    /// The reprojected history is reset where its depth and this pixel's differ by more than
    /// this share (the TAA resolve's rejection test and default).
    pub depth_tolerance: f32,
    /// The hybrid pass (Sec. 5.3.2): AFIS (the variant on the prefiltered chain) on some tiles,
    /// the separable passes on the others; None: the variant alone.
    pub hybrid: Option<Hybrid>,
    /// Algorithm 3's m (SPVG estimates it) or eq. 5.20's m = n̂·γ; SPVG variants only.
    pub distant_count: DistantCount,
}

impl SssPassSettings {
    /// Every setting the pass reads, with what was expected.
    pub fn validate(&self) -> Result<(), String> {
        self.spvg.validate()?;
        if let Some(split) = &self.split {
            split.validate()?;
        }
        if !(self.monitor_gamma > 0.0 && self.monitor_gamma.is_finite()) {
            return Err(format!(
                "monitor_gamma {}; expected a positive number (1: linear luminance)",
                self.monitor_gamma
            ));
        }
        if !(self.depth_tolerance > 0.0) {
            return Err(format!(
                "depth_tolerance {}; expected a positive share of the depth",
                self.depth_tolerance
            ));
        }
        if let Some(h) = &self.hybrid {
            h.validate()?;
            if matches!(self.variant, SssVariant::Separable { .. }) {
                return Err("hybrid with the Separable variant; expected the Monte Carlo variant its AFIS tiles run (Adaptive, OnlineCv, ConstantCv, Fixed), the separable taps in hybrid's own taps".into());
            }
            if self.prefilter.is_none() {
                return Err("hybrid without prefilter; the hybrid's Monte Carlo tiles run AFIS, expected e.g. prefilter: ()".into());
            }
        }
        self.mip_levels().map(|_| ())
    }

    /// The MIP levels the pass reads (0: no prefiltering); errors for a bad prefilter or one
    /// with the separable variant, which takes no samples to prefilter.
    pub fn mip_levels(&self) -> Result<u32, String> {
        match (self.prefilter, self.variant) {
            (None, _) => Ok(0),
            (Some(_), SssVariant::Separable { .. }) => Err("prefilter with Separable; the MIP chain serves the Monte Carlo variants (Adaptive, OnlineCv, ConstantCv, Fixed)".into()),
            (Some(p), _) => p.validate().map(|()| p.levels),
        }
    }
}

/// The thesis monitors "gamma-corrected luminance" (Sec. 4.4) without naming the curve; 2.2
/// is the display gamma of the SDR output its Table 7.3 runs recorded.
pub const MONITOR_GAMMA: f32 = 2.2;

impl Default for SssPassSettings {
    fn default() -> Self {
        Self {
            variant: SssVariant::Adaptive,
            spvg: SpvgSettings::default(),
            fast_inverse: true,
            eps_a: 1e-6,
            a0: 1000.0,
            a_cv: 1e-6,
            seed: 1,
            prefilter: None,
            split: Some(Split::default()),
            monitor_gamma: MONITOR_GAMMA,
            depth_tolerance: taa::TaaSettings::default().depth_tolerance,
            hybrid: None,
            distant_count: DistantCount::Estimated,
        }
    }
}

/// Eq. 7.1's sums for one Burley sample at q, radius r (drawn with density ∝ `pdf_s`): per
/// channel Σ w·L and Σ w over the sample's bilinear taps that are SSS texels, w = the tap's
/// bilinear weight × R(r')·r'/pdf (∝ pdf_c(r')/pdf_s(r)), r' = √(r² + ΔD²) with ΔD the tap's
/// depth difference to the centre in pixels. Texels off the mask weigh nothing (no centre
/// stand-in): the ratio renormalises over what is left.
fn bilateral_sample(
    frame: &SssFrame,
    q: [f32; 2],
    r: f32,
    pdf_s: f32,
    centre_w: f32,
    d: [f32; 3],
    num: &mut [f32; 3],
    den: &mut [f32; 3],
) {
    let (w, h) = (frame.width as i32, frame.height as i32);
    let (x, y) = (q[0] - 0.5, q[1] - 0.5);
    let (x0, y0) = (x.floor(), y.floor());
    let (fx, fy) = (x - x0, y - y0);
    // Clamp before the cast: radii in the far tail are huge.
    let (xi, yi) = (x0.clamp(-2.0, w as f32 + 1.0) as i32, y0.clamp(-2.0, h as f32 + 1.0) as i32);
    for (dx, dy, b) in [
        (0, 0, (1.0 - fx) * (1.0 - fy)),
        (1, 0, fx * (1.0 - fy)),
        (0, 1, (1.0 - fx) * fy),
        (1, 1, fx * fy),
    ] {
        let (i, j) = ((xi + dx).clamp(0, w - 1), (yi + dy).clamp(0, h - 1));
        let t = frame.irradiance[(j * w + i) as usize];
        if t[3] <= 0.0 || b <= 0.0 {
            continue;
        }
        let dz = depth_difference_px(frame.focal_px, centre_w, t[3]);
        let rp = (r * r + dz * dz).sqrt();
        for c in 0..3 {
            let wc = b * radial_pdf(rp, d[c]) / pdf_s;
            num[c] += wc * t[c];
            den[c] += wc;
        }
    }
}

/// ΔD of eq. 7.1 in pixels at the centre: depth = focal/w, scaled by the centre's w.
pub fn depth_difference_px(focal_px: f32, centre_w: f32, w: f32) -> f32 {
    if focal_px > 0.0 { focal_px * (centre_w / w - 1.0) } else { 0.0 }
}

/// The frame's MIP chain when the settings prefilter.
pub fn mip_chain(frame: &SssFrame, settings: &SssPassSettings) -> Option<MipChain> {
    settings
        .prefilter
        .map(|p| MipChain::build(frame.width, frame.height, &frame.irradiance, p.levels))
}

/// One pixel's scattering: the direct term (1 − γ)·B (eq. 5.16), the distant term γ·L_s from m
/// Burley samples over r > r0 (eq. 5.17) normalised by eq. 7.1, and their sum.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Scattered {
    pub rgb: [f32; 3],
    pub direct: [f32; 3],
    pub distant: [f32; 3],
}

/// m Burley samples around pixel (x, y) over the distant region (the whole disc without a
/// split): L_s per channel by eq. 7.1, read from `chain` at eq. 5.12's level when given (AFIS,
/// Algorithm 2; no bilateral weight there), else bilinear with the bilateral weights; then
/// eq. 5.18. m = 0 gives the direct term alone.
pub fn scatter(
    frame: &SssFrame,
    settings: &SssPassSettings,
    chain: Option<&MipChain>,
    frame_index: u32,
    x: u32,
    y: u32,
    m: u32,
) -> Scattered {
    let pixel = y * frame.width + x;
    let t = frame.irradiance[pixel as usize];
    let centre = [t[0], t[1], t[2]];
    let ds = frame.d_sample() * t[3];
    let d = frame.d_px.map(|d| d * t[3]);
    let sp = split::pixel_split(settings.split.as_ref(), d, ds);
    let offset = pixel_offset(settings.seed, frame_index, pixel);
    let (mut num, mut den) = ([0.0f32; 3], [0.0f32; 3]);
    for j in 0..m {
        let u = r2_point(offset, j);
        let r = sample_radius(split::distant_u(u[0], sp.u0), ds, settings.fast_inverse);
        let phi = 2.0 * std::f32::consts::PI * u[1];
        let q = [x as f32 + 0.5 + r * phi.cos(), y as f32 + 0.5 + r * phi.sin()];
        let ps = radial_pdf(r, ds);
        match (chain, settings.prefilter) {
            (Some(chain), Some(p)) => {
                let l = chain.fetch(prefilter::level(r, ps, m, p.a, p.levels), q, centre);
                for c in 0..3 {
                    let w = radial_pdf(r, d[c]) / ps;
                    num[c] += w * l[c];
                    den[c] += w;
                }
            }
            _ => bilateral_sample(frame, q, r, ps, t[3], d, &mut num, &mut den),
        }
    }
    let mut out = Scattered { rgb: [0.0; 3], direct: [0.0; 3], distant: [0.0; 3] };
    for c in 0..3 {
        let ls = if m > 0 && den[c] > 0.0 { num[c] / den[c] } else { centre[c] };
        out.direct[c] = (1.0 - sp.gamma[c]) * centre[c];
        out.distant[c] = if m > 0 { sp.gamma[c] * ls } else { 0.0 };
        out.rgb[c] = out.direct[c] + out.distant[c];
    }
    out
}

/// The monitored luminance in the thesis's encoding (Sec. 4.4: gamma-corrected): Y^(1/γ_m),
/// γ_m = `monitor_gamma` (1: linear).
pub fn encode(y: f32, monitor_gamma: f32) -> f32 {
    if monitor_gamma == 1.0 { y } else { y.max(0.0).powf(1.0 / monitor_gamma) }
}

/// One pixel's step: count, samples, histories (the Monte Carlo variants).
fn pixel_step(
    frame: &SssFrame,
    settings: &SssPassSettings,
    chain: Option<&MipChain>,
    frame_index: u32,
    x: u32,
    y: u32,
    prev: &PixelHistory,
) -> (PixelResult, PixelHistory) {
    let t = frame.irradiance[(y * frame.width + x) as usize];
    if t[3] <= 0.0 {
        return (PixelResult { rgb: [t[0], t[1], t[2]], count: 0 }, PixelHistory::default());
    }
    let d = frame.d_px.map(|d| d * t[3]);
    let sp = split::pixel_split(settings.split.as_ref(), d, frame.d_sample() * t[3]);
    // Algorithm 3, lines 1-2: no distant samples, nothing to track (the history restarts).
    if settings.split.is_some_and(|s| sp.gamma_s < s.eps_u) {
        let s = scatter(frame, settings, chain, frame_index, x, y, 0);
        return (PixelResult { rgb: s.rgb, count: 0 }, PixelHistory::default());
    }
    let st = spvg::state(&prev.spvg, &settings.spvg);
    // n̂: SPVG's count (eq. 4.9), kept in the history; m: the distant samples taken.
    let (n_hat, m) = match settings.variant {
        SssVariant::Fixed { count } => (count, count),
        SssVariant::Separable { .. } => {
            unreachable!("the separable variant runs as two 1-D passes in `step`")
        }
        _ => {
            let n = spvg::sample_count(&st, &settings.spvg);
            (n, split::distant_count(settings.distant_count, n, sp.gamma_s))
        }
    };
    let s = scatter(frame, settings, chain, frame_index, x, y, m);
    // f̄ = L_o − (1 − γ)B (eq. 6.22), ḡ = G(t) = γB(t) (eq. 6.14), luminance, encoded.
    let f = encode(luminance(s.distant), settings.monitor_gamma);
    let b = [t[0], t[1], t[2]];
    let g = encode(luminance(std::array::from_fn(|c| sp.gamma[c] * b[c])), settings.monitor_gamma);
    let a = match settings.variant {
        SssVariant::OnlineCv if st.valid => prev.cv.coefficient(settings.eps_a, settings.a0, f, g),
        SssVariant::OnlineCv | SssVariant::ConstantCv => 1.0,
        _ => 0.0,
    };
    // Res(t) = f̄ − a G(t) (eq. 6.23); AS (a = 0) tracks the distant term alone.
    let monitored = f - a * g;
    let cv = if st.valid { prev.cv.update(settings.a_cv, f, g) } else { EmCovariance::start(f, g) };
    (
        PixelResult { rgb: s.rgb, count: m },
        PixelHistory { spvg: spvg::update(&st, &settings.spvg, monitored, n_hat), cv, w: t[3] },
    )
}

/// The whole image: results and the next frame's histories (`history` empty = cold start;
/// the separable variant keeps none). Errors: a separable kernel that cannot be built.
pub fn step(
    frame: &SssFrame,
    settings: &SssPassSettings,
    frame_index: u32,
    history: &[PixelHistory],
) -> (Vec<PixelResult>, Vec<PixelHistory>) {
    let count = (frame.width * frame.height) as usize;
    if let SssVariant::Separable { taps } = settings.variant {
        let kernel = separable::kernel(taps, frame.d_px).unwrap_or_else(|e| panic!("{e}"));
        return (separable::step(frame, &kernel), vec![PixelHistory::default(); count]);
    }
    if let Some(h) = &settings.hybrid {
        // P1: the whole image's Monte Carlo step; the hybrid keeps it on its AFIS tiles.
        return hybrid::step(frame, h, monte_carlo_step(frame, settings, frame_index, history));
    }
    monte_carlo_step(frame, settings, frame_index, history)
}

/// Every pixel's Monte Carlo step (the variant, AFIS where the settings prefilter) with the
/// reprojected histories.
pub(crate) fn monte_carlo_step(
    frame: &SssFrame,
    settings: &SssPassSettings,
    frame_index: u32,
    history: &[PixelHistory],
) -> (Vec<PixelResult>, Vec<PixelHistory>) {
    let count = (frame.width * frame.height) as usize;
    let chain = mip_chain(frame, settings);
    let mut results = Vec::with_capacity(count);
    let mut next = Vec::with_capacity(count);
    for y in 0..frame.height {
        for x in 0..frame.width {
            let i = (y * frame.width + x) as usize;
            let prev = reproject::reproject(
                history,
                frame.motion.get(i).copied(),
                (x, y),
                (frame.width, frame.height),
                frame.irradiance[i][3],
                settings.depth_tolerance,
            );
            let (r, h) = pixel_step(frame, settings, chain.as_ref(), frame_index, x, y, &prev);
            results.push(r);
            next.push(h);
        }
    }
    (results, next)
}
