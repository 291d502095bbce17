//! Judging one claim on per-seed values: a relation between two methods by the one-sided upper
//! bound of their paired differences, a value, ratio or difference by its two-sided interval
//! against the claim's band. Too few seeds, a missing value or an interval wider than the band
//! is "not comparable", with the reason.

use super::claims::Comparison;
use crate::suite::student_t;
use crate::suite::welch::Sample;
use crate::suite::window::Window;

#[derive(Clone, Debug, PartialEq)]
pub enum Verdict {
    Reproduced,
    NotReproduced,
    NotComparable(String),
}

impl Verdict {
    pub fn name(&self) -> &'static str {
        match self {
            Verdict::Reproduced => "reproduced",
            Verdict::NotReproduced => "not reproduced",
            Verdict::NotComparable(_) => "not comparable",
        }
    }
}

/// A claim's outcome: what flicker measured (with its interval) and the verdict.
#[derive(Clone, Debug, PartialEq)]
pub struct Judged {
    pub flicker: String,
    pub verdict: Verdict,
    /// The per-seed values the verdict was judged on (for a relation both methods', the first
    /// method's first); empty when there were none.
    pub values: Vec<f64>,
}

fn not_comparable(reason: String) -> Judged {
    Judged { flicker: "-".into(), verdict: Verdict::NotComparable(reason), values: Vec::new() }
}

/// The mean of `values` and the half-width of its two-sided `confidence` interval.
pub(crate) fn interval(values: &[f64], confidence: f64) -> (f64, f64) {
    let s = Sample::of(values);
    let t = student_t::quantile(0.5 + confidence / 2.0, (s.n - 1) as f64);
    (s.mean, t * s.standard_error())
}

/// `a` below `b` by the one-sided `confidence` upper bound of the paired differences.
fn paired_below(a: Vec<f64>, b: Vec<f64>, confidence: f64) -> Judged {
    if a.len() != b.len() || a.len() < 2 {
        return not_comparable(format!(
            "{} and {} seed(s); a paired interval needs the same seeds, at least 2",
            a.len(),
            b.len()
        ));
    }
    let diffs: Vec<f64> = a.iter().zip(&b).map(|(x, y)| x - y).collect();
    let d = Sample::of(&diffs);
    let t = student_t::quantile(confidence, (d.n - 1) as f64);
    let upper = d.mean + t * d.standard_error();
    let flicker = format!(
        "{:.4} vs {:.4}; difference {:+.4}, {:.0}% upper bound {upper:+.4} ({} seeds)",
        Sample::of(&a).mean,
        Sample::of(&b).mean,
        d.mean,
        confidence * 100.0,
        d.n
    );
    let verdict = if upper < 0.0 { Verdict::Reproduced } else { Verdict::NotReproduced };
    Judged { flicker, verdict, values: [a, b].concat() }
}

/// Two methods' per-seed values combined seed by seed (`what`: "a ratio"), or why not.
fn paired(
    a: Result<Vec<f64>, String>,
    b: Result<Vec<f64>, String>,
    what: &str,
    combine: impl Fn(Vec<f64>, Vec<f64>) -> Result<Vec<f64>, String>,
) -> Result<Vec<f64>, String> {
    let (a, b) = (a?, b?);
    if a.len() != b.len() {
        return Err(format!("{} and {} seed(s); {what} needs the same seeds", a.len(), b.len()));
    }
    combine(a, b)
}

/// Judges `comparison` with `per_seed(method, window)`: one value per seed (the same seeds, in
/// the same order, for every method) over `window` (`None`: the claim's), or why there is none.
pub fn judge(
    comparison: &Comparison,
    per_seed: &dyn Fn(&str, Option<&Window>) -> Result<Vec<f64>, String>,
) -> Judged {
    let values = |m: &str| per_seed(m, None).map_err(|e| format!("{m}: {e}"));
    let band = |v: Vec<f64>, value: f64, tolerance: f64, confidence: f64| {
        if v.len() < 2 {
            let mut j =
                not_comparable(format!("{} seed(s); an interval needs at least 2", v.len()));
            j.values = v;
            return j;
        }
        let (mean, half) = interval(&v, confidence);
        let (lo, hi) = (mean - half, mean + half);
        let flicker = format!("{mean:.4} [{lo:.4}, {hi:.4}] ({} seeds)", v.len());
        let verdict = if lo >= value - tolerance && hi <= value + tolerance {
            Verdict::Reproduced
        } else if hi < value - tolerance || lo > value + tolerance {
            Verdict::NotReproduced
        } else {
            Verdict::NotComparable(format!(
                "the {:.0}% interval straddles the band {value} ± {tolerance}; more seeds",
                confidence * 100.0
            ))
        };
        Judged { flicker, verdict, values: v }
    };
    match comparison {
        Comparison::NotComparable { reason, .. } => not_comparable(reason.clone()),
        Comparison::Below { method, than, confidence } => match (values(method), values(than)) {
            (Ok(a), Ok(b)) => paired_below(a, b, *confidence),
            (Err(e), _) | (_, Err(e)) => not_comparable(e),
        },
        // Rising: the earlier window's values below the claim's window's, paired per seed.
        Comparison::Rises { method, from, confidence } => {
            let before = per_seed(method, Some(from))
                .map_err(|e| format!("{method} over {}: {e}", from.name()));
            match (before, values(method)) {
                (Ok(a), Ok(b)) => paired_below(a, b, *confidence),
                (Err(e), _) | (_, Err(e)) => not_comparable(e),
            }
        }
        Comparison::Value { method, value, tolerance, confidence } => match values(method) {
            Ok(v) => band(v, *value, *tolerance, *confidence),
            Err(e) => not_comparable(e),
        },
        Comparison::Ratio { method, to, value, tolerance, confidence } => {
            let per_seed = |a: Vec<f64>, b: Vec<f64>| {
                if b.contains(&0.0) {
                    return Err(format!("{to} is 0 in a seed; no ratio"));
                }
                Ok(a.iter().zip(&b).map(|(x, y)| x / y).collect())
            };
            match paired(values(method), values(to), "a ratio", per_seed) {
                Ok(r) => band(r, *value, *tolerance, *confidence),
                Err(e) => not_comparable(e),
            }
        }
        Comparison::LogRatio { method, to, expect, confidence } => {
            match (values(method), values(to)) {
                (Ok(a), Ok(b)) => super::log_ratio::judge(a, b, (method, to), expect, *confidence),
                (Err(e), _) | (_, Err(e)) => not_comparable(e),
            }
        }
        Comparison::Difference { method, to, value, tolerance, confidence } => {
            let per_seed =
                |a: Vec<f64>, b: Vec<f64>| Ok(a.iter().zip(&b).map(|(x, y)| x - y).collect());
            match paired(values(method), values(to), "a difference", per_seed) {
                Ok(d) => band(d, *value, *tolerance, *confidence),
                Err(e) => not_comparable(e),
            }
        }
    }
}
