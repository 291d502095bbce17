//! The screen-space SSS pass on the CPU (the reference the WGSL pass is tested against, and the
//! test bed of SPVG and the control variates): per SSS pixel, SPVG picks the count n, n Burley
//! samples of the demodulated diffuse irradiance around the pixel give the scattered value
//! (eq. 5.2, divided by A: the albedo is applied after the pass), and the histories update.

use super::control_variates::EmCovariance;
use super::prefilter::{self, MipChain, Prefilter};
use super::sampling::{luminance, pixel_offset, r2_point, radial_pdf, sample_radius};
use super::separable;
use super::spvg::{self, SpvgHistory, SpvgSettings};
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
pub struct SssSettings {
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
}

impl SssSettings {
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

impl Default for SssSettings {
    fn default() -> Self {
        Self {
            variant: SssVariant::Adaptive,
            spvg: SpvgSettings::default(),
            fast_inverse: true,
            eps_a: 1e-6,
            a0: 1000.0,
            a_cv: 0.005,
            seed: 1,
            prefilter: None,
        }
    }
}

/// One frame's input, row-major: per pixel the demodulated diffuse irradiance (rgb) and w, the
/// pixels per unit of d at that pixel (0: not an SSS pixel; 1 when d is given in pixels); and
/// the profile's d per channel (in pixels where w = 1).
#[derive(Clone, Debug)]
pub struct SssFrame {
    pub width: u32,
    pub height: u32,
    pub irradiance: Vec<[f32; 4]>,
    pub d_px: [f32; 3],
}

impl SssFrame {
    /// The channel that radii are sampled for: the widest profile.
    pub fn d_sample(&self) -> f32 {
        self.d_px[0].max(self.d_px[1]).max(self.d_px[2])
    }
}

/// A pixel's histories: SPVG's H and the control variates' J.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct PixelHistory {
    pub spvg: SpvgHistory,
    pub cv: EmCovariance,
}

/// A pixel's result: the scattered irradiance and the count it took.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct PixelResult {
    pub rgb: [f32; 3],
    pub count: u32,
}

/// The irradiance at q (pixel units, texel centres at +0.5), bilinear, clamped to the image;
/// texels outside the SSS mask read as the centre pixel's (no bleeding across profiles).
fn fetch(frame: &SssFrame, q: [f32; 2], centre: [f32; 3]) -> [f32; 3] {
    let w = frame.width as i32;
    prefilter::bilinear(w, frame.height as i32, q, |i, j| {
        let t = frame.irradiance[(j * w + i) as usize];
        if t[3] > 0.0 { [t[0], t[1], t[2]] } else { centre }
    })
}

/// The frame's MIP chain when the settings prefilter.
pub fn mip_chain(frame: &SssFrame, settings: &SssSettings) -> Option<MipChain> {
    settings
        .prefilter
        .map(|p| MipChain::build(frame.width, frame.height, &frame.irradiance, p.levels))
}

/// n Burley samples around pixel (x, y): (1/n) Σ L(q_j) pdf_c(r_j)/pdf_s(r_j) per channel c, L
/// read from `chain` at eq. 5.12's level when given (AFIS, Algorithm 2), else bilinear.
pub fn scatter(
    frame: &SssFrame,
    settings: &SssSettings,
    chain: Option<&MipChain>,
    frame_index: u32,
    x: u32,
    y: u32,
    n: u32,
) -> [f32; 3] {
    let pixel = y * frame.width + x;
    let t = frame.irradiance[pixel as usize];
    let centre = [t[0], t[1], t[2]];
    let ds = frame.d_sample() * t[3];
    let d = frame.d_px.map(|d| d * t[3]);
    let offset = pixel_offset(settings.seed, frame_index, pixel);
    let mut sum = [0.0f32; 3];
    for j in 0..n {
        let u = r2_point(offset, j);
        let r = sample_radius(u[0], ds, settings.fast_inverse);
        let phi = 2.0 * std::f32::consts::PI * u[1];
        let q = [x as f32 + 0.5 + r * phi.cos(), y as f32 + 0.5 + r * phi.sin()];
        let ps = radial_pdf(r, ds);
        let l = match (chain, settings.prefilter) {
            (Some(chain), Some(p)) => {
                chain.fetch(prefilter::level(r, ps, n, p.a, p.levels), q, centre)
            }
            _ => fetch(frame, q, centre),
        };
        for c in 0..3 {
            sum[c] += l[c] * (radial_pdf(r, d[c]) / ps);
        }
    }
    sum.map(|s| s / n as f32)
}

/// One pixel's step: count, samples, histories (the Monte Carlo variants).
fn pixel_step(
    frame: &SssFrame,
    settings: &SssSettings,
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
    let st = spvg::state(&prev.spvg, &settings.spvg);
    let n = match settings.variant {
        SssVariant::Fixed { count } => count,
        SssVariant::Separable { .. } => {
            unreachable!("the separable variant runs as two 1-D passes in `step`")
        }
        _ => spvg::sample_count(&st, &settings.spvg),
    };
    let rgb = scatter(frame, settings, chain, frame_index, x, y, n);
    let f = luminance(rgb);
    let g = luminance([t[0], t[1], t[2]]);
    let a = match settings.variant {
        SssVariant::OnlineCv if st.valid => prev.cv.coefficient(settings.eps_a, settings.a0, f, g),
        SssVariant::OnlineCv | SssVariant::ConstantCv => 1.0,
        _ => 0.0,
    };
    let monitored = f - a * g;
    let cv = if st.valid { prev.cv.update(settings.a_cv, f, g) } else { EmCovariance::start(f, g) };
    (
        PixelResult { rgb, count: n },
        PixelHistory { spvg: spvg::update(&st, &settings.spvg, monitored, n), cv },
    )
}

/// The whole image: results and the next frame's histories (`history` empty = cold start;
/// the separable variant keeps none). Errors: a separable kernel that cannot be built.
pub fn step(
    frame: &SssFrame,
    settings: &SssSettings,
    frame_index: u32,
    history: &[PixelHistory],
) -> (Vec<PixelResult>, Vec<PixelHistory>) {
    let count = (frame.width * frame.height) as usize;
    if let SssVariant::Separable { taps } = settings.variant {
        let kernel = separable::kernel(taps, frame.d_px).unwrap_or_else(|e| panic!("{e}"));
        return (separable::step(frame, &kernel), vec![PixelHistory::default(); count]);
    }
    let chain = mip_chain(frame, settings);
    let empty = PixelHistory::default();
    let mut results = Vec::with_capacity(count);
    let mut next = Vec::with_capacity(count);
    for y in 0..frame.height {
        for x in 0..frame.width {
            let i = (y * frame.width + x) as usize;
            let (r, h) = pixel_step(
                frame,
                settings,
                chain.as_ref(),
                frame_index,
                x,
                y,
                history.get(i).unwrap_or(&empty),
            );
            results.push(r);
            next.push(h);
        }
    }
    (results, next)
}
