//! A claim's smallest effect that matters (`smallest_effect`), in the statistic's unit or as a
//! share of a baseline.

use serde::Deserialize;

/// A claim's smallest effect that matters, in the statistic's unit or as a share.
#[derive(Clone, Debug, PartialEq, Deserialize)]
pub enum Effect {
    /// `Absolute(0.005)`: in the statistic's unit (a ratio's for `Ratio` and `LogRatio`).
    Absolute(f64),
    /// `Relative(0.05)`: a share of the baseline: the `than` method's mean for `Below`, the
    /// claim window's for `Rises`, the paper's value for a value, the factor for `LogRatio`.
    Relative(f64),
}

impl Effect {
    /// δ in the statistic's unit, `base` the value a relative margin is a share of.
    pub fn margin(&self, base: f64) -> f64 {
        match *self {
            Effect::Absolute(d) => d,
            Effect::Relative(r) => r * base.abs(),
        }
    }

    pub fn describe(&self) -> String {
        match *self {
            Effect::Absolute(d) => format!("{d}"),
            Effect::Relative(r) => format!("{}%", r * 100.0),
        }
    }

    /// A margin above 0; a share below 1.
    pub fn check(&self) -> Result<(), String> {
        match *self {
            Effect::Absolute(d) if !(d.is_finite() && d > 0.0) => Err(format!(
                "smallest_effect: Absolute({d}); expected a number above 0, e.g. Absolute(0.005)"
            )),
            Effect::Relative(r) if !(r.is_finite() && r > 0.0 && r < 1.0) => Err(format!(
                "smallest_effect: Relative({r}); expected a share between 0 and 1, e.g. Relative(0.05)"
            )),
            _ => Ok(()),
        }
    }
}
