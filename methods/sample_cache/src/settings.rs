//! Scenario settings of the stable sample cache; serde defaults are the paper's (section 4).

use serde::{Deserialize, Serialize};

/// Which cached samples get their visibility retraced each frame (sections 3.2 and 3.4).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize, Default)]
pub enum Retrace {
    /// One sample per pixel, round robin.
    Single,
    /// Every sample, every frame.
    Multi,
    /// One sample per 4x4 block plus every sample of pixels that fail the slope test (eq. 2).
    #[default]
    Adaptive,
}

/// Which cached samples get shaded each frame (sections 3.3 and 3.5).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize, Default)]
pub enum ShadingMode {
    /// One visible sample per pixel, round robin.
    #[default]
    Uniform,
    /// One sample per 4x4 block plus the budget by importance 1 / (1 + c_s).
    Adaptive,
}

#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct SampleCacheSettings {
    /// N, slots per pixel (at most 16: the 32-bit mask holds 2 bits per slot).
    pub slots: u32,
    /// n_target, visible samples per pixel the density control aims at.
    pub n_target: f32,
    /// δ, tolerance of the density control.
    pub delta: f32,
    /// ε0, relative distance under which a retrace hit counts as the sample itself.
    pub epsilon0: f32,
    /// ε1 of eq. 2.
    pub epsilon1: f32,
    /// Side of the block that gets one base-rate trace and one base-rate shade per frame (4).
    pub base_block: u32,
    /// M, buckets of the log importance histogram.
    pub buckets: u32,
    /// Minimum blend weight of a new radiance sample, max(1 / (c_s + 1), alpha). 0 (default): the
    /// plain running mean of the paper's main results (§3.3); 0.1 is the fixed α of its glossy
    /// stereo test (§5.2).
    pub alpha: f32,
    /// App. C (glossy materials): the minimum blend weight of a surface sample from its
    /// material's GGX roughness, α_min = (1 − α_GGX)·0.5 + α_GGX·0.1, instead of `alpha`
    /// (background samples keep `alpha`). Off by default.
    pub roughness_alpha: bool,
    pub retrace: Retrace,
    pub shading: ShadingMode,
    /// Shading invocations per frame as a fraction of the pixel count (1 = 100%); only adaptive
    /// shading takes another rate than 1.
    pub shading_rate: f32,
    /// The image resolved by TAA (`taa`) over the cache's reconstruction and its closest
    /// visible samples' primary attributes: the paper applies TAA to every method for its error
    /// figures. The cache itself is unchanged; `playback` runs the resolve.
    pub taa: bool,
}

impl Default for SampleCacheSettings {
    fn default() -> Self {
        Self {
            slots: 12,
            n_target: 4.0,
            delta: 1.0,
            epsilon0: 0.001,
            epsilon1: 0.005,
            base_block: 4,
            buckets: 13,
            alpha: 0.0,
            roughness_alpha: false,
            retrace: Retrace::Adaptive,
            shading: ShadingMode::Uniform,
            shading_rate: 1.0,
            taa: false,
        }
    }
}

impl SampleCacheSettings {
    /// Refuses settings the passes cannot honour, naming the field and the accepted range.
    pub fn validate(&self) -> Result<(), String> {
        if !(1..=16).contains(&self.slots) {
            return Err(format!(
                "slots must be in 1..=16 (two mask bits per slot in 32 bits), got {}",
                self.slots
            ));
        }
        if !(self.n_target >= 1.0 && self.n_target <= self.slots as f32) {
            return Err(format!(
                "n_target must be in [1, slots = {}], got {}",
                self.slots, self.n_target
            ));
        }
        if !(self.delta >= 0.0 && self.delta.is_finite()) {
            return Err(format!("delta must be >= 0, got {}", self.delta));
        }
        for (name, v) in [("epsilon0", self.epsilon0), ("epsilon1", self.epsilon1)] {
            if !(0.0..1.0).contains(&v) {
                return Err(format!("{name} must be in [0, 1), got {v}"));
            }
        }
        if !(1..=64).contains(&self.base_block) {
            return Err(format!("base_block must be in 1..=64, got {}", self.base_block));
        }
        if !(1..=16).contains(&self.buckets) {
            return Err(format!("buckets must be in 1..=16, got {}", self.buckets));
        }
        if !(0.0..=1.0).contains(&self.alpha) {
            return Err(format!("alpha must be in [0, 1], got {}", self.alpha));
        }
        if !(self.shading_rate >= 0.0 && self.shading_rate <= self.slots as f32) {
            return Err(format!("shading_rate must be in [0, slots], got {}", self.shading_rate));
        }
        // Uniform shading shades one visible sample per pixel by construction (section 3.3); a
        // rate there would be ignored and the reported samples per pixel would be wrong.
        if self.shading == ShadingMode::Uniform && self.shading_rate != 1.0 {
            return Err(format!(
                "shading_rate {} needs shading: Adaptive (Uniform shades one sample per pixel: rate 1)",
                self.shading_rate
            ));
        }
        Ok(())
    }

    /// Short name, e.g. `ssc_adaptive`, `ssc_multi_as` (adaptive shading), `ssc_adaptive_taa`.
    pub fn label(&self) -> String {
        let retrace = match self.retrace {
            Retrace::Single => "single",
            Retrace::Multi => "multi",
            Retrace::Adaptive => "adaptive",
        };
        let shading = match self.shading {
            ShadingMode::Uniform => "",
            ShadingMode::Adaptive => "_as",
        };
        format!("ssc_{retrace}{shading}{}", if self.taa { "_taa" } else { "" })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_shading_rate_needs_adaptive_shading() {
        let uniform = SampleCacheSettings { shading_rate: 0.7, ..Default::default() };
        let e = uniform.validate().unwrap_err();
        assert!(e.contains("shading_rate 0.7 needs shading: Adaptive"), "{e}");
        assert!(
            SampleCacheSettings { shading: ShadingMode::Adaptive, ..uniform }.validate().is_ok()
        );
        assert!(SampleCacheSettings::default().validate().is_ok());
    }
}
