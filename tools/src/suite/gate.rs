//! Judging one gate for one (case, method): the per-seed window means of the new runs against
//! an absolute limit, against the baseline's with Welch's one-sided test, or against another
//! method of the same runs with a paired one-sided t test.

use super::measurement::CaseRuns;
use super::spec::{Bound, Gate};
use super::welch::{self, Sample};

#[derive(Clone, Debug, PartialEq)]
pub enum Verdict {
    Pass,
    /// Worse than the bound (with the gate's confidence, for relative bounds).
    Fail,
    /// Could not be judged: no baseline, a window without values, ...
    Error(String),
}

#[derive(Clone, Debug, PartialEq)]
pub struct GateResult {
    pub case: String,
    pub method: String,
    pub gate: String,
    pub new: Option<Sample>,
    pub baseline: Option<Sample>,
    /// Welch's p-value (relative gates).
    pub p_value: Option<f64>,
    pub verdict: Verdict,
    /// One line a person reads first.
    pub detail: String,
}

impl GateResult {
    pub fn passed(&self) -> bool {
        self.verdict == Verdict::Pass
    }
}

/// Judges `gate` for `method` of `case`; `baseline` is the blessed runs of the same case.
pub fn judge(
    gate: &Gate,
    case: &str,
    method: &str,
    new: &CaseRuns,
    baseline: Option<&CaseRuns>,
) -> GateResult {
    let mut result = GateResult {
        case: case.into(),
        method: method.into(),
        gate: gate.describe(),
        new: None,
        baseline: None,
        p_value: None,
        verdict: Verdict::Pass,
        detail: String::new(),
    };
    let values = match new.per_seed(method, gate.metric, &gate.window) {
        Ok(v) => v,
        Err(e) => {
            result.verdict = Verdict::Error(e.clone());
            result.detail = e;
            return result;
        }
    };
    let sample = Sample::of(&values);
    result.new = Some(sample);
    // Both bounds are judged on "how much worse": positive = worse, whatever the metric's direction.
    let sign = if gate.metric.higher_is_better() { -1.0 } else { 1.0 };
    match &gate.bound {
        Bound::Better { than } => {
            let other = match new.per_seed(than, gate.metric, &gate.window) {
                Ok(v) => v,
                Err(e) => {
                    result.verdict = Verdict::Error(format!("{than}: {e}"));
                    result.detail = format!("{than}: {e}");
                    return result;
                }
            };
            // Paired by seed: positive differences = the gate's method is worse.
            let diffs: Vec<f64> = values.iter().zip(&other).map(|(a, b)| sign * (a - b)).collect();
            let d = Sample::of(&diffs);
            let se = d.standard_error();
            let df = (d.n.max(2) - 1) as f64;
            // P(mean difference >= 0) under the t model; no spread: the sign decides.
            let p_value = if se > 0.0 {
                1.0 - super::student_t::cdf(-d.mean / se, df)
            } else if d.mean < 0.0 {
                0.0
            } else {
                1.0
            };
            result.p_value = Some(p_value);
            result.verdict =
                if p_value < 1.0 - gate.confidence { Verdict::Pass } else { Verdict::Fail };
            result.detail = format!(
                "{method} {:.5} vs {than} {:.5}; paired difference {:+.5} ± {se:.5} (standard error, {} seeds), p = {p_value:.4} (pass below {:.2})",
                sample.mean,
                Sample::of(&other).mean,
                sign * d.mean,
                d.n,
                1.0 - gate.confidence
            );
        }
        Bound::Absolute { limit } => {
            let limit = *limit;
            let worse = sign * (sample.mean - limit) > 0.0;
            result.verdict = if worse { Verdict::Fail } else { Verdict::Pass };
            result.detail =
                format!("mean {:.5} over {} seeds, limit {limit}", sample.mean, sample.n);
        }
        Bound::Relative { tolerance } => {
            let tolerance = *tolerance;
            let base = match baseline.map(|b| b.per_seed(method, gate.metric, &gate.window)) {
                Some(Ok(v)) => Sample::of(&v),
                Some(Err(e)) => {
                    result.verdict = Verdict::Error(format!("baseline: {e}"));
                    result.detail =
                        format!("baseline: {e}; bless the suite again if the case changed");
                    return result;
                }
                None => {
                    result.verdict = Verdict::Error("no baseline for this case".into());
                    result.detail = "no baseline for this case; bless the suite again".into();
                    return result;
                }
            };
            result.baseline = Some(base);
            let signed = |s: Sample| Sample { mean: sign * s.mean, ..s };
            let margin = tolerance * base.mean.abs();
            let test = welch::one_sided(&signed(sample), &signed(base), margin);
            result.p_value = Some(test.p_value);
            result.verdict =
                if test.worse(gate.confidence) { Verdict::Fail } else { Verdict::Pass };
            result.detail = format!(
                "new {:.5} ± {:.5} vs baseline {:.5} ± {:.5} (standard errors); worse by {:+.5}, allowed {margin:.5}; Welch t = {:.2}, df = {:.1}, p = {:.4} (fail below {:.2})",
                sample.mean,
                sample.standard_error(),
                base.mean,
                base.standard_error(),
                test.difference,
                test.t,
                test.df,
                test.p_value,
                1.0 - gate.confidence
            );
        }
    }
    result
}
