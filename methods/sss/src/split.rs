//! The direct/distant split of the thesis's Sec. 5.3.1 (eqs. 5.14-5.20): the disc of radius r0
//! that one texel covers, r0 = Z·√(w² + h²)/2 (√2/2 pixels: our radii are in pixels), is
//! integrated analytically as B(p, p)·cdf(r0) (eq. 5.16), and only the distant region r > r0 is
//! sampled, with u drawn from (cdf(r0), 1] (r = g((1 − ξ)·cdf(r0) + ξ), eq. 5.17). Eq. 5.18 blends
//! the two with the distant energy ratio γ: for Burley's profile γ = 1 − cdf(r0) (Table 5.1);
//! eq. 5.20 and Algorithm 3 (lines 1-2) take no distant samples where γ < ε_u. f32, the same
//! operations as shaders/sss_pass.wgsl.

use serde::{Deserialize, Serialize};

/// The radius in pixels of the disc a texel covers: half its diagonal.
pub const R0_PX: f32 = std::f32::consts::FRAC_1_SQRT_2;

/// The split's settings; `Sss(split: (gamma: None, eps_u: 0.01))` is the thesis's (Sec. 7.4).
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct Split {
    /// γ of eq. 5.18: None = Table 5.1's Burley row, 1 − cdf(r0) per channel at the pixel's d;
    /// Some(c) = a constant blend (Table 5.1's pre-integrated separable row), c in [0, 1].
    pub gamma: Option<f32>,
    /// ε_u of eq. 5.20: no distant samples where the sampled channel's γ < ε_u (biased: the
    /// distant energy is dropped there), in [0, 1].
    pub eps_u: f32,
}

impl Default for Split {
    fn default() -> Self {
        Self { gamma: None, eps_u: 0.01 }
    }
}

impl Split {
    pub fn validate(&self) -> Result<(), String> {
        if let Some(g) = self.gamma
            && !(0.0..=1.0).contains(&g)
        {
            return Err(format!("split gamma {g}; expected a number in [0, 1] (or None)"));
        }
        if !(0.0..=1.0).contains(&self.eps_u) {
            return Err(format!("split eps_u {}; expected a number in [0, 1]", self.eps_u));
        }
        Ok(())
    }
}

/// How the distant sample count m follows SPVG's estimate (Sec. 5.3.1).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
pub enum DistantCount {
    /// Algorithm 3 (and the text after eq. 5.20: "we can directly estimate m̂ with Eq. 4.9"):
    /// SPVG's count is m itself, clamped to [β_min, β_max].
    #[default]
    Estimated,
    /// Eq. 5.20 as written: SPVG's count is n̂ (the total, clamped to [β_min, β_max], kept in
    /// the history's n̄) and m = max(1, ⌊n̂·γ + ½⌋), γ the sampled channel's.
    GammaScaled,
}

/// m of eq. 5.20 from SPVG's n̂ (`GammaScaled`), or n̂ itself (`Estimated`).
pub fn distant_count(rule: DistantCount, n_hat: u32, gamma_s: f32) -> u32 {
    match rule {
        DistantCount::Estimated => n_hat,
        DistantCount::GammaScaled => ((n_hat as f32 * gamma_s + 0.5).floor() as u32).max(1),
    }
}

/// Burley's radial cdf in f32 (eq. 5.3).
pub fn cdf(r: f32, d: f32) -> f32 {
    1.0 - 0.25 * (-r / d).exp() - 0.75 * (-r / (3.0 * d)).exp()
}

/// A pixel's split: r0, the sampled channel's cdf(r0) (where its distant u starts), γ per
/// channel and γ of the sampled channel (eq. 5.20's test).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PixelSplit {
    pub r0: f32,
    pub u0: f32,
    pub gamma: [f32; 3],
    pub gamma_s: f32,
}

/// The split at a pixel whose profiles have d = `d` per channel and `ds` sampled (pixels). No
/// split (None): r0 = 0, γ = 1, every sample distant (the whole disc sampled).
pub fn pixel_split(split: Option<&Split>, d: [f32; 3], ds: f32) -> PixelSplit {
    match split {
        None => PixelSplit { r0: 0.0, u0: 0.0, gamma: [1.0; 3], gamma_s: 1.0 },
        Some(s) => {
            let u0 = cdf(R0_PX, ds);
            let (gamma, gamma_s) = match s.gamma {
                Some(c) => ([c; 3], c),
                None => (d.map(|d| 1.0 - cdf(R0_PX, d)), 1.0 - u0),
            };
            PixelSplit { r0: R0_PX, u0, gamma, gamma_s }
        }
    }
}

/// ξ in [0, 1) mapped onto the distant part of the cdf, (1 − ξ)·cdf(r0) + ξ (eq. 5.17).
pub fn distant_u(xi: f32, u0: f32) -> f32 {
    (1.0 - xi) * u0 + xi
}
