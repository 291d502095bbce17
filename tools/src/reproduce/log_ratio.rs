//! A paired relation of two methods on a ratio statistic (a bias, a std, an error): per seed
//! the log ratio ln(a / b) of the two methods' values in the same run, and the Student t
//! interval of its mean over seeds. Logs, because the claims are about factors ("roughly three
//! times more bias", "13 to 32 times less std") and a factor's spread is symmetric in the log;
//! the mean of the logs is the log of the geometric mean ratio, which the report shows.
//!
//! `Below(1.0)` is a sign claim (a below b); `Below(0.5)` says "at most half". `Near(value: 3.0,
//! tolerance: 0.5)` is the paper's ratio: the interval of the geometric mean ratio must lie
//! within value ± tolerance (the paper's stated precision, e.g. "roughly three").

use serde::Deserialize;

use super::judge::{Judged, Verdict, interval};
use crate::suite::metric::Metric;
use crate::suite::student_t;
use crate::suite::welch::Sample;

/// What the paper says about the ratio a / b.
#[derive(Clone, Debug, PartialEq, Deserialize)]
#[serde(deny_unknown_fields)]
pub enum RatioExpectation {
    /// a / b below this factor, by the one-sided upper bound of the geometric mean ratio.
    Below(f64),
    /// a / b = value ± tolerance, by the two-sided interval of the geometric mean ratio.
    Near { value: f64, tolerance: f64 },
}

impl RatioExpectation {
    pub fn describe(&self) -> String {
        match self {
            RatioExpectation::Below(r) => format!("below {r}"),
            RatioExpectation::Near { value, tolerance } => format!("= {value} ± {tolerance}"),
        }
    }

    /// A factor a ratio can be compared with in the log: positive, the band's low end too.
    pub fn check(&self) -> Result<(), String> {
        match *self {
            RatioExpectation::Below(r) if !(r.is_finite() && r > 0.0) => {
                Err(format!("Below({r}); expected a factor above 0, e.g. Below(1.0)"))
            }
            RatioExpectation::Near { value, tolerance }
                if !(value.is_finite() && tolerance.is_finite() && tolerance >= 0.0)
                    || value - tolerance <= 0.0 =>
            {
                Err(format!(
                    "Near(value: {value}, tolerance: {tolerance}); expected value − tolerance above 0 (a band of positive ratios)"
                ))
            }
            _ => Ok(()),
        }
    }
}

/// The statistics whose ratio means something: positive quantities. PSNR and JOD are already
/// logarithmic scores (their `Difference` is the relation), and a time's ratio is left to
/// `Ratio` on its own claim.
pub fn check_metric(metric: Metric) -> Result<(), String> {
    match metric {
        Metric::Psnr | Metric::SssPsnr | Metric::Cvvdp => Err(format!(
            "a log ratio of {}, a logarithmic score; expected a positive statistic (an error, a bias, a std) or Difference",
            metric.name()
        )),
        _ => Ok(()),
    }
}

fn not_comparable(reason: String, values: Vec<f64>) -> Judged {
    Judged { flicker: "-".into(), verdict: Verdict::NotComparable(reason), values }
}

/// Judges a / b against `expect` on the per-seed values of the same runs.
pub fn judge(
    a: Vec<f64>,
    b: Vec<f64>,
    (method, to): (&str, &str),
    expect: &RatioExpectation,
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
    let logs: Vec<f64> = a.iter().zip(&b).map(|(x, y)| (x / y).ln()).collect();
    let per_seed = logs.iter().map(|l| format!("{:.3}", l.exp())).collect::<Vec<_>>().join(", ");
    let n = logs.len();
    match *expect {
        RatioExpectation::Below(r) => {
            let s = Sample::of(&logs);
            let t = student_t::quantile(confidence, (n - 1) as f64);
            let upper = (s.mean + t * s.standard_error()).exp();
            let flicker = format!(
                "ratio per seed {per_seed}; geometric mean {:.3}, {:.0}% upper bound {upper:.3} ({n} seeds)",
                s.mean.exp(),
                confidence * 100.0
            );
            let verdict = if upper < r { Verdict::Reproduced } else { Verdict::NotReproduced };
            Judged { flicker, verdict, values }
        }
        RatioExpectation::Near { value, tolerance } => {
            let (mean, half) = interval(&logs, confidence);
            let (lo, hi) = ((mean - half).exp(), (mean + half).exp());
            let flicker = format!(
                "ratio per seed {per_seed}; geometric mean {:.3} [{lo:.3}, {hi:.3}] ({n} seeds)",
                mean.exp()
            );
            let (low, high) = (value - tolerance, value + tolerance);
            let verdict = if lo >= low && hi <= high {
                Verdict::Reproduced
            } else if hi < low || lo > high {
                Verdict::NotReproduced
            } else {
                Verdict::NotComparable(format!(
                    "the {:.0}% interval straddles the band {value} ± {tolerance}; more seeds",
                    confidence * 100.0
                ))
            };
            Judged { flicker, verdict, values }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn below(r: f64) -> RatioExpectation {
        RatioExpectation::Below(r)
    }

    /// ln ratios ln 0.2, ln 0.25, ln 0.2: mean −1.535, standard error 0.0744, t(0.95, 2) =
    /// 2.920: upper bound exp(−1.318) = 0.268. Below 1 and below 0.3, not below 0.25.
    #[test]
    fn a_factor_is_judged_by_the_upper_bound_of_the_geometric_mean() {
        let (a, b) = (vec![0.02, 0.05, 0.1], vec![0.1, 0.2, 0.5]);
        let j = |r| judge(a.clone(), b.clone(), ("a", "b"), &below(r), 0.95);
        assert_eq!(j(1.0).verdict, Verdict::Reproduced, "{}", j(1.0).flicker);
        assert_eq!(j(0.3).verdict, Verdict::Reproduced);
        assert_eq!(j(0.25).verdict, Verdict::NotReproduced, "{}", j(0.25).flicker);
        assert!(j(1.0).flicker.contains("0.200, 0.250, 0.200"), "{}", j(1.0).flicker);
        assert!(j(1.0).flicker.contains("upper bound 0.268"), "{}", j(1.0).flicker);
        // Scale-free: the same factors at values a thousand times larger judge alike, where a
        // difference of values would not.
        let big = judge(
            a.iter().map(|x| x * 1e3).collect(),
            b.iter().map(|x| x * 1e3).collect(),
            ("a", "b"),
            &below(0.25),
            0.95,
        );
        assert_eq!(big.verdict, Verdict::NotReproduced);
    }

    /// The paper's "roughly three": ratios 2.9, 3.0, 3.1 (geometric mean 2.999, 95% interval
    /// [2.76, 3.26]) are within 3 ± 0.5; ratios near 2 are outside; a wide spread straddles.
    #[test]
    fn a_paper_ratio_is_judged_by_its_interval_against_the_band() {
        let near = RatioExpectation::Near { value: 3.0, tolerance: 0.5 };
        let b = vec![1.0, 2.0, 4.0];
        let j = |r: [f64; 3]| {
            judge(b.iter().zip(r).map(|(x, r)| x * r).collect(), b.clone(), ("a", "b"), &near, 0.95)
        };
        assert_eq!(
            j([2.9, 3.0, 3.1]).verdict,
            Verdict::Reproduced,
            "{}",
            j([2.9, 3.0, 3.1]).flicker
        );
        assert_eq!(j([1.9, 2.0, 2.1]).verdict, Verdict::NotReproduced);
        assert!(matches!(j([2.0, 3.0, 4.5]).verdict, Verdict::NotComparable(_)));
    }

    #[test]
    fn values_a_log_cannot_take_are_not_comparable_with_the_method_named() {
        let j = judge(vec![0.1, 0.0], vec![0.2, 0.2], ("jackknife", "naive"), &below(1.0), 0.95);
        assert!(
            matches!(&j.verdict, Verdict::NotComparable(w) if w.contains("jackknife is 0")),
            "{:?}",
            j.verdict
        );
        assert_eq!(j.values.len(), 4);
        let one = judge(vec![0.1], vec![0.2], ("a", "b"), &below(1.0), 0.95);
        assert!(matches!(one.verdict, Verdict::NotComparable(_)));
    }

    #[test]
    fn factors_and_statistics_a_log_ratio_cannot_judge_are_refused() {
        assert!(below(0.0).check().is_err());
        assert!(below(1.0).check().is_ok());
        assert!(RatioExpectation::Near { value: 0.5, tolerance: 0.5 }.check().is_err());
        assert!(RatioExpectation::Near { value: 3.0, tolerance: 0.5 }.check().is_ok());
        assert!(check_metric(Metric::Psnr).is_err());
        assert!(check_metric(Metric::RmsBias).is_ok());
    }
}
