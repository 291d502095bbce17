//! A paired relation of two methods on a ratio statistic (a bias, a std, an error): per seed
//! the log ratio ln(a / b) of the two methods' values in the same run, and the Student t
//! interval of its mean over seeds. Logs, because the claims are about factors ("roughly three
//! times more bias", "13 to 32 times less std") and a factor's spread is symmetric in the log;
//! the mean of the logs is the log of the geometric mean ratio, which the report shows.
//!
//! `Below(1.0)` is a sign claim (a below b); `Below(0.5)` says "at most half". `Near(3.0)` is
//! the paper's ratio ("roughly three"). The claim's smallest effect that matters sets the edge
//! (`Below(f)`: the ratio below f − δ, or f · (1 − r) for a relative margin) or the band
//! (`Near(v)`: v ± δ), both compared in the log (`log_region`).

use serde::Deserialize;

use super::effect::Effect;
use super::verdict::{Judged, Region, judge_effects, not_comparable, num};
use crate::suite::metric::Metric;

/// What the paper says about the ratio a / b.
#[derive(Clone, Debug, PartialEq, Deserialize)]
#[serde(deny_unknown_fields)]
pub enum RatioExpectation {
    /// a / b below this factor (less the claim's margin), by the upper bound of the geometric
    /// mean ratio.
    Below(f64),
    /// a / b = this factor ± the claim's margin, by the interval of the geometric mean ratio.
    Near(f64),
}

impl RatioExpectation {
    pub fn describe(&self) -> String {
        match self {
            RatioExpectation::Below(r) => format!("below {r}"),
            RatioExpectation::Near(v) => format!("near {v}"),
        }
    }

    /// A factor a ratio can be compared with in the log, its margin leaving a positive ratio.
    pub fn check(&self, effect: &Effect) -> Result<(), String> {
        match *self {
            RatioExpectation::Below(r) | RatioExpectation::Near(r)
                if !(r.is_finite() && r > 0.0) =>
            {
                Err(format!("{}; expected a factor above 0, e.g. Below(1.0)", self.describe()))
            }
            _ => log_region(self, effect).map(|_| ()).map_err(|e| {
                format!("{} with the smallest effect {}: {e}", self.describe(), effect.describe())
            }),
        }
    }
}

/// The statistics whose ratio means something: positive quantities. PSNR and JOD are already
/// logarithmic scores (their `Difference` is the relation), and a time's ratio is left to
/// `Ratio` on its own claim.
pub fn check_metric(metric: Metric) -> Result<(), String> {
    match metric {
        m if m.higher_is_better() => Err(format!(
            "a log ratio of {}, a logarithmic score; expected a positive statistic (an error, a bias, a std) or Difference",
            metric.name()
        )),
        _ => Ok(()),
    }
}

/// Judges a / b against `expect`, with the claim's smallest effect, on the per-seed values
/// of the same runs.
pub fn judge(
    a: Vec<f64>,
    b: Vec<f64>,
    (method, to): (&str, &str),
    expect: &RatioExpectation,
    effect: &Effect,
    confidence: f64,
) -> Judged {
    let values = [a.clone(), b.clone()].concat();
    if a.len() != b.len() || a.len() < 2 {
        return not_comparable(
            format!(
                "{} and {} seed(s); a paired interval needs the same seeds, at least 2",
                a.len(),
                b.len()
            ),
            values,
        );
    }
    if let Some((m, v)) = a
        .iter()
        .map(|v| (method, v))
        .chain(b.iter().map(|v| (to, v)))
        .find(|(_, v)| !(v.is_finite() && **v > 0.0))
    {
        return not_comparable(
            format!("{m} is {v} in a seed; a log ratio needs values above 0"),
            values,
        );
    }
    let region = match log_region(expect, effect) {
        Ok(r) => r,
        Err(e) => return not_comparable(e, values),
    };
    let logs: Vec<f64> = a.iter().zip(&b).map(|(x, y)| (x / y).ln()).collect();
    let per_seed = logs.iter().map(|l| format!("{:.3}", l.exp())).collect::<Vec<_>>().join(", ");
    let (verdict, mean, lo, hi) = judge_effects(&logs, region, confidence);
    let paper = match region {
        Region::Below { edge } => format!("paper below {}", num(edge.exp())),
        Region::Within { low, high } => {
            format!("paper {} .. {}", num(low.exp()), num(high.exp()))
        }
    };
    let flicker = format!(
        "{method} / {to} per seed {per_seed}; geometric mean {} [{}, {}], {paper} ({} seeds)",
        num(mean.exp()),
        num(lo.exp()),
        num(hi.exp()),
        logs.len()
    );
    Judged { flicker, verdict, values }
}

/// The region of a log ratio's expectation in the log, with δ from `effect`, or why the margin
/// leaves no positive ratio.
pub fn log_region(expect: &RatioExpectation, effect: &Effect) -> Result<Region, String> {
    let ln = |r: f64, what: &str| {
        if r > 0.0 && r.is_finite() {
            Ok(r.ln())
        } else {
            Err(format!("{what} {r}; the margin leaves no positive ratio"))
        }
    };
    match *expect {
        RatioExpectation::Below(f) => {
            let edge = match *effect {
                Effect::Absolute(d) => f - d,
                Effect::Relative(r) => f * (1.0 - r),
            };
            Ok(Region::Below { edge: ln(edge, "the edge")? })
        }
        RatioExpectation::Near(v) => {
            let d = effect.margin(v);
            Ok(Region::Within {
                low: ln(v - d, "the band's low end")?,
                high: ln(v + d, "the band's high end")?,
            })
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::reproduce::verdict::Verdict;

    fn below(r: f64) -> RatioExpectation {
        RatioExpectation::Below(r)
    }

    const ABS: Effect = Effect::Absolute(0.01);

    /// ln ratios ln 0.2, ln 0.25, ln 0.2: mean −1.535, standard error 0.0744, t(0.95, 2) =
    /// 2.920: bounds exp(−1.7522) = 0.1734 and exp(−1.3179) = 0.2677. Below 1 less 5% and below
    /// 0.3 less 0.01; inconclusive against 0.25 less 0.01 (the edge 0.24 inside the bounds);
    /// not below 0.15 less 0.01 (the edge 0.14 under the lower bound).
    #[test]
    fn a_factor_is_judged_by_the_bounds_of_the_geometric_mean() {
        let (a, b) = (vec![0.02, 0.05, 0.1], vec![0.1, 0.2, 0.5]);
        let j = |r, e: &Effect| judge(a.clone(), b.clone(), ("a", "b"), &below(r), e, 0.95);
        let rel = Effect::Relative(0.05);
        assert_eq!(j(1.0, &rel).verdict, Verdict::Reproduced, "{}", j(1.0, &rel).flicker);
        assert_eq!(j(0.3, &ABS).verdict, Verdict::Reproduced);
        assert!(matches!(j(0.25, &ABS).verdict, Verdict::Inconclusive { seeds: Some(_) }));
        assert_eq!(j(0.15, &ABS).verdict, Verdict::NotReproduced, "{}", j(0.15, &ABS).flicker);
        let f = j(1.0, &rel).flicker;
        assert!(f.contains("0.200, 0.250, 0.200"), "{f}");
        assert!(f.contains("[0.1734, 0.2677]") && f.contains("paper below 0.9500"), "{f}");
        // Scale-free: the same factors at values a thousand times larger judge alike, where a
        // difference of values would not.
        let big = judge(
            a.iter().map(|x| x * 1e3).collect(),
            b.iter().map(|x| x * 1e3).collect(),
            ("a", "b"),
            &below(0.15),
            &ABS,
            0.95,
        );
        assert_eq!(big.verdict, Verdict::NotReproduced);
    }

    /// The paper's "roughly three" (3 ± 0.5): ratios 2.9, 3.0, 3.1 are within it; ratios near
    /// 2 are outside; a wide spread holds an edge.
    #[test]
    fn a_paper_ratio_is_judged_by_its_interval_against_the_band() {
        let near = RatioExpectation::Near(3.0);
        let b = vec![1.0, 2.0, 4.0];
        let half = Effect::Absolute(0.5);
        let j = |r: [f64; 3]| {
            let a = b.iter().zip(r).map(|(x, r)| x * r).collect();
            judge(a, b.clone(), ("a", "b"), &near, &half, 0.95)
        };
        assert_eq!(
            j([2.9, 3.0, 3.1]).verdict,
            Verdict::Reproduced,
            "{}",
            j([2.9, 3.0, 3.1]).flicker
        );
        assert_eq!(j([1.9, 2.0, 2.1]).verdict, Verdict::NotReproduced);
        assert!(matches!(j([2.0, 3.0, 4.5]).verdict, Verdict::Inconclusive { .. }));
    }

    #[test]
    fn values_a_log_cannot_take_are_not_comparable_with_the_method_named() {
        let j =
            judge(vec![0.1, 0.0], vec![0.2, 0.2], ("jackknife", "naive"), &below(1.0), &ABS, 0.95);
        assert!(
            matches!(&j.verdict, Verdict::NotComparable(w) if w.contains("jackknife is 0")),
            "{:?}",
            j.verdict
        );
        assert_eq!(j.values.len(), 4);
        let one = judge(vec![0.1], vec![0.2], ("a", "b"), &below(1.0), &ABS, 0.95);
        assert!(matches!(one.verdict, Verdict::NotComparable(_)));
    }

    #[test]
    fn factors_and_statistics_a_log_ratio_cannot_judge_are_refused() {
        assert!(below(0.0).check(&ABS).is_err());
        assert!(below(1.0).check(&ABS).is_ok());
        // A margin that leaves no positive ratio.
        assert!(below(0.01).check(&Effect::Absolute(0.01)).is_err());
        assert!(RatioExpectation::Near(0.5).check(&Effect::Absolute(0.5)).is_err());
        assert!(RatioExpectation::Near(3.0).check(&Effect::Absolute(0.5)).is_ok());
        assert!(check_metric(Metric::Psnr).is_err());
        assert!(check_metric(Metric::shipped("RmsBias")).is_ok());
    }
}
