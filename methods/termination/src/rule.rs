//! The termination rules a scenario selects (§4.2, §4.3, §6): what `Termination(rule: ...)`
//! names, with the paper's parameters.

use serde::{Deserialize, Serialize};

/// Where a path ends into the cache.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub enum TerminationRule {
    /// §4.2: the longest prefix whose path variance Σ P_j stays within t; the overshooting vertex
    /// is blended with α (eq. 5). `relative`: t times the squared cache value at the first hit
    /// (§5, relative variance bounding).
    VarianceBounding {
        t: f64,
        #[serde(default)]
        relative: bool,
    },
    /// §4.3: greedy comparison of the current and the deferred MSE for `s` accumulated samples.
    MseMinimisation {
        s: f64,
        /// The current MSE may exceed the deferred one by this factor and still terminate.
        #[serde(default = "default_margin")]
        margin: f64,
        /// The deferred squared bias is clamped to this fraction of the local one (divided by
        /// the margin): "90% below the local bias".
        #[serde(default = "default_bias_clamp")]
        bias_clamp: f64,
    },
    /// NRC's area-spread heuristic [Müller et al. 2021]: terminate once the spread of the path
    /// behind the primary vertex exceeds c times the primary footprint; never at the first hit.
    AreaSpread { c: f64 },
    /// Into the cache at the first hit (t = 0).
    FirstVertex,
    /// No cache: plain path tracing (t = ∞).
    PathTracing,
}

pub fn default_margin() -> f64 {
    1.1
}

pub fn default_bias_clamp() -> f64 {
    0.1
}

impl TerminationRule {
    /// Input errors in the rule's parameters.
    pub fn validate(&self) -> Result<(), String> {
        let finite_nonneg = |name: &str, v: f64| {
            if v.is_finite() && v >= 0.0 {
                Ok(())
            } else {
                Err(format!("{name} must be a finite number >= 0, got {v}"))
            }
        };
        match *self {
            TerminationRule::VarianceBounding { t, .. } => finite_nonneg("VarianceBounding t", t),
            TerminationRule::MseMinimisation { s, margin, bias_clamp } => {
                if !(s.is_finite() && s >= 1.0) {
                    return Err(format!("MseMinimisation s (sample target) must be >= 1, got {s}"));
                }
                if !(margin.is_finite() && margin >= 1.0) {
                    return Err(format!("MseMinimisation margin must be >= 1, got {margin}"));
                }
                if !(bias_clamp > 0.0 && bias_clamp < 1.0) {
                    return Err(format!(
                        "MseMinimisation bias_clamp must be in (0, 1), got {bias_clamp}"
                    ));
                }
                Ok(())
            }
            TerminationRule::AreaSpread { c } => finite_nonneg("AreaSpread c", c),
            TerminationRule::FirstVertex | TerminationRule::PathTracing => Ok(()),
        }
    }

    /// Short label: `vb_0.1`, `vb_rel_1`, `mse_100`, `spread_0.01`, `first_vertex`, `pt`.
    pub fn label(&self) -> String {
        match *self {
            TerminationRule::VarianceBounding { t, relative } => {
                format!("vb_{}{t}", if relative { "rel_" } else { "" })
            }
            TerminationRule::MseMinimisation { s, .. } => format!("mse_{s}"),
            TerminationRule::AreaSpread { c } => format!("spread_{c}"),
            TerminationRule::FirstVertex => "first_vertex".into(),
            TerminationRule::PathTracing => "pt".into(),
        }
    }
}
