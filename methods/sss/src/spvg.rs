//! Single pass variance guiding (SPVG, thesis Ch. 4): a per-pixel history H = (μ, σ², n̄) of the
//! monitored value S, updated with an exponential moving average and variance (eqs. 4.3, 4.4),
//! sets the next frame's sample count (eqs. 4.9, 4.10), with the history reset on disocclusion
//! (eqs. 4.11, 4.12). f32, the same operations as shaders/spvg.wgsl.

use serde::{Deserialize, Serialize};

/// SPVG's parameters (thesis values: α0 = 0.2, κ = 0.2, counts in [8, 64], σ0² = 1e-4 in the
/// dynamic tests of Sec. 7.4).
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct SpvgSettings {
    /// α0: the history's exponential weight where the history is valid.
    pub alpha0: f32,
    /// κ of eq. 4.9: the share of the correction term Δ applied in one frame.
    pub kappa: f32,
    /// σ0²: the target variance of the per-frame mean.
    pub sigma0_sq: f32,
    /// β_min, β_max: the sample count's clamp.
    pub n_min: u32,
    pub n_max: u32,
}

impl Default for SpvgSettings {
    fn default() -> Self {
        Self { alpha0: 0.2, kappa: 0.2, sigma0_sq: 1e-4, n_min: 8, n_max: 64 }
    }
}

impl SpvgSettings {
    pub fn validate(&self) -> Result<(), String> {
        if !(self.alpha0 > 0.0 && self.alpha0 <= 1.0) {
            return Err(format!("SPVG alpha0 {} must be in (0, 1]", self.alpha0));
        }
        if !(0.0..=1.0).contains(&self.kappa) {
            return Err(format!("SPVG kappa {} must be in [0, 1]", self.kappa));
        }
        if !(self.sigma0_sq > 0.0) {
            return Err(format!("SPVG sigma0_sq {} must be > 0", self.sigma0_sq));
        }
        if self.n_min == 0 || self.n_min > self.n_max {
            return Err(format!(
                "SPVG counts [{}, {}] must satisfy 1 <= n_min <= n_max",
                self.n_min, self.n_max
            ));
        }
        Ok(())
    }
}

/// H_i of one pixel: μ (EMA of S), σ² (EMV of S), n̄ (EMA of the count), and whether the pixel
/// was a subsurface pixel last frame (C_s ≠ 0 of eq. 4.11).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct SpvgHistory {
    pub mu: f32,
    pub sigma2: f32,
    pub nbar: f32,
    pub valid: bool,
}

/// The history as this frame reads it: α = M'(α0, Λ) (eq. 4.11), σ̂² (eq. 4.12) and the n̄ to
/// start from (β_min on disocclusion, the thesis's max(n̂, β)).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SpvgState {
    pub alpha: f32,
    pub sigma2: f32,
    pub nbar: f32,
    pub mu: f32,
    pub valid: bool,
}

pub fn state(h: &SpvgHistory, s: &SpvgSettings) -> SpvgState {
    if h.valid {
        SpvgState { alpha: s.alpha0, sigma2: h.sigma2, nbar: h.nbar, mu: h.mu, valid: true }
    } else {
        SpvgState { alpha: 1.0, sigma2: s.sigma0_sq, nbar: s.n_min as f32, mu: 0.0, valid: false }
    }
}

/// n̂ = κ Δ + E[n̄] (eq. 4.9) with Δ = (σ² − σ0²)/σ0² · n̄ · (k − 1) (eq. 4.10),
/// E[n̄] = σ²/σ0² · n̄ and k = 2/α − 1; clamped to [n_min, n_max] and rounded.
pub fn sample_count(st: &SpvgState, s: &SpvgSettings) -> u32 {
    let k = 2.0 / st.alpha - 1.0;
    let ratio = st.sigma2 / s.sigma0_sq;
    let expected = ratio * st.nbar;
    let delta = (ratio - 1.0) * st.nbar * (k - 1.0);
    let n = s.kappa * delta + expected;
    // NaN (never expected) falls to n_min.
    let n = if n.is_nan() { s.n_min as f32 } else { n.clamp(s.n_min as f32, s.n_max as f32) };
    (n + 0.5).floor() as u32
}

/// Eqs. 4.2-4.4 after sampling: μ, σ² and n̄ with this frame's S and count n. On disocclusion
/// (α = 1) μ = S, n̄ = n and σ² = σ0² (eq. 4.12).
pub fn update(st: &SpvgState, s: &SpvgSettings, value: f32, n: u32) -> SpvgHistory {
    let a = st.alpha;
    if !st.valid {
        return SpvgHistory { mu: value, sigma2: s.sigma0_sq, nbar: n as f32, valid: true };
    }
    let diff = value - st.mu;
    SpvgHistory {
        mu: (1.0 - a) * st.mu + a * value,
        sigma2: (1.0 - a) * st.sigma2 + a * (1.0 - a) * diff * diff,
        nbar: (1.0 - a) * st.nbar + a * n as f32,
        valid: true,
    }
}
