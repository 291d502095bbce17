//! The neural cache's speed targets as shares of the FMA ceiling measured in the same run (the
//! lab's restatement of the targets in GFLOP/s, which depended on the machine): inference at
//! least 25% of the ceiling, a training step with sparse grid updates at least 10%, the blend's
//! extra cost at most 5% of a whole 160x90 NIRC frame.

use crate::nirc_frames::Table1;
use crate::nirc_throughput::BenchReport;

#[derive(Clone, Debug, serde::Serialize)]
pub struct Target {
    pub measure: String,
    /// The measured share, in percent.
    pub percent: f64,
    /// The target, in percent: a floor when `at_least`, else a ceiling.
    pub target_percent: f64,
    pub at_least: bool,
    /// None when the target applies to something not measured (the blend's share of a frame
    /// of another resolution, or no frames).
    pub met: Option<bool>,
}

fn target(measure: &str, percent: f64, target_percent: f64, at_least: bool) -> Target {
    let met = if at_least { percent >= target_percent } else { percent <= target_percent };
    Target { measure: measure.into(), percent, target_percent, at_least, met: Some(met) }
}

/// The targets beside the measured shares. The training step without sparse updates has no
/// target of its own; it is listed against the sparse step's, to show what sparse updates buy.
pub fn targets(r: &BenchReport, frames: Option<&Table1>) -> Vec<Target> {
    let mut out = vec![
        target("EMA-only inference, % of the FMA ceiling", r.infer_percent_of_peak, 25.0, true),
        target(
            "training step with sparse grid updates, % of the FMA ceiling",
            r.train_sparse_percent_of_peak,
            10.0,
            true,
        ),
        target(
            "training step, dense (every parameter), % of the FMA ceiling",
            r.train_percent_of_peak,
            10.0,
            true,
        ),
    ];
    let mut blend = target(
        "the blend's extra cost, % of EMA-only's whole 160x90 NIRC frame",
        frames.map_or(f64::NAN, |t| t.blend_overhead_frame_percent),
        5.0,
        false,
    );
    if frames.is_none_or(|t| t.resolution != (160, 90)) {
        blend.met = None;
    }
    out.push(blend);
    out
}

pub fn markdown(targets: &[Target]) -> String {
    let mut s = String::from("\n| target | measured | target | met |\n|---|---:|---:|---|\n");
    for t in targets {
        let met = match t.met {
            Some(true) => "yes",
            Some(false) => "no",
            None => "not measured",
        };
        let bound = if t.at_least { "≥" } else { "≤" };
        s.push_str(&format!(
            "| {} | {:.1}% | {bound} {:.0}% | {met} |\n",
            t.measure, t.percent, t.target_percent
        ));
    }
    s
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn floors_and_ceilings_are_met_on_their_side() {
        assert_eq!(target("a", 25.0, 25.0, true).met, Some(true));
        assert_eq!(target("a", 24.9, 25.0, true).met, Some(false));
        assert_eq!(target("b", 5.0, 5.0, false).met, Some(true));
        assert_eq!(target("b", 5.1, 5.0, false).met, Some(false));
        assert_eq!(target("b", f64::NAN, 5.0, false).met, Some(false));
    }
}
