//! A claim's outcome and how an interval of effects decides it: the verdicts, the region of
//! effects the paper claims, the interval of a mean between one-sided bounds, and the seeds that
//! would likely settle an inconclusive claim (`judge` turns each comparison into effects).

use crate::suite::student_t;
use crate::suite::welch::Sample;

#[derive(Clone, Debug, PartialEq)]
pub enum Verdict {
    Reproduced,
    NotReproduced,
    /// The interval holds an edge of the paper's region. `seeds`: about how many seeds would
    /// likely settle it (`None`: the mean sits on the edge, or more than `MAX_SEEDS`).
    Inconclusive {
        seeds: Option<usize>,
    },
    /// The data cannot be judged (or the lab does not measure the claim), with the reason.
    NotComparable(String),
}

/// The verdicts' names, in the order the report counts them.
pub const VERDICTS: [&str; 4] = ["reproduced", "not reproduced", "inconclusive", "not comparable"];

/// The largest number of seeds an inconclusive verdict names.
pub const MAX_SEEDS: usize = 10_000;

impl Verdict {
    pub fn name(&self) -> &'static str {
        match self {
            Verdict::Reproduced => VERDICTS[0],
            Verdict::NotReproduced => VERDICTS[1],
            Verdict::Inconclusive { .. } => VERDICTS[2],
            Verdict::NotComparable(_) => VERDICTS[3],
        }
    }

    /// The name with what settles an inconclusive verdict or the reason for not comparable.
    pub fn text(&self) -> String {
        match self {
            Verdict::Inconclusive { seeds: Some(n) } => {
                format!("inconclusive (about {n} seeds would likely settle it)")
            }
            Verdict::Inconclusive { seeds: None } => format!(
                "inconclusive (the mean sits on the margin's edge: no number of seeds up to {MAX_SEEDS} likely settles it)"
            ),
            Verdict::NotComparable(why) => format!("not comparable: {why}"),
            v => v.name().to_string(),
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

pub(crate) fn not_comparable(reason: String, values: Vec<f64>) -> Judged {
    let flicker = if values.is_empty() { "not measured".into() } else { "-".into() };
    Judged { flicker, verdict: Verdict::NotComparable(reason), values }
}

/// The mean of `values` and the half-width of its two-sided `confidence` interval.
pub(crate) fn interval(values: &[f64], confidence: f64) -> (f64, f64) {
    let s = Sample::of(values);
    let t = student_t::quantile(0.5 + confidence / 2.0, (s.n - 1) as f64);
    (s.mean, t * s.standard_error())
}

/// The mean of `effects` and its one-sided `confidence` lower and upper bounds.
pub(crate) fn bounds(effects: &[f64], confidence: f64) -> (f64, f64, f64) {
    let s = Sample::of(effects);
    let t = student_t::quantile(confidence, (s.n - 1) as f64);
    let half = t * s.standard_error();
    (s.mean, s.mean - half, s.mean + half)
}

/// Where the paper's claim puts the effect, given its smallest effect that matters.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Region {
    /// A relation: effects below `edge` (0 − δ for a difference).
    Below { edge: f64 },
    /// A value: effects within [low, high] (the paper's number ± δ).
    Within { low: f64, high: f64 },
}

impl Region {
    fn edges(self) -> Vec<f64> {
        match self {
            Region::Below { edge } => vec![edge],
            Region::Within { low, high } => vec![low, high],
        }
    }
}

/// The verdict of an interval [lo, hi] against the paper's region (the rule of the docs'
/// table: `rules`). Inconclusive carries no seeds here (`judge_effects` estimates them).
pub fn decide(region: Region, lo: f64, hi: f64) -> Verdict {
    let undecided = Verdict::Inconclusive { seeds: None };
    match region {
        Region::Below { edge } if hi < edge => Verdict::Reproduced,
        Region::Below { edge } if lo > edge => Verdict::NotReproduced,
        Region::Below { .. } => undecided,
        Region::Within { low, high } if lo >= low && hi <= high => Verdict::Reproduced,
        Region::Within { low, high } if hi < low || lo > high => Verdict::NotReproduced,
        Region::Within { .. } => undecided,
    }
}

/// About how many seeds would likely settle an interval that holds an edge: the smallest n
/// at which, were the effect's true mean and spread the observed ones, the interval would
/// clear the nearest edge with 80% probability, (t(confidence) + t(0.8)) · s / √n below the
/// distance from the mean to that edge. `None` when the mean sits on the edge or n would pass
/// `MAX_SEEDS`.
pub fn seeds_to_settle(effects: &[f64], region: Region, confidence: f64) -> Option<usize> {
    let s = Sample::of(effects);
    let sd = s.standard_error() * (s.n as f64).sqrt();
    let distance = region.edges().iter().map(|e| (s.mean - e).abs()).fold(f64::INFINITY, f64::min);
    if !(distance > 0.0 && sd.is_finite()) {
        return None;
    }
    let settles = |n: usize| {
        let df = (n - 1) as f64;
        (student_t::quantile(confidence, df) + student_t::quantile(0.8, df)) * sd
            / (n as f64).sqrt()
            <= distance
    };
    // The left side falls with n: bisect on it.
    let (mut lo, mut hi) = (s.n.max(2), MAX_SEEDS);
    if !settles(hi) {
        return None;
    }
    while hi - lo > 1 {
        let mid = (lo + hi) / 2;
        if settles(mid) { hi = mid } else { lo = mid }
    }
    Some(hi)
}

/// The verdict of per-seed `effects` against `region`, with the seeds that would likely settle
/// an inconclusive one; also the mean and bounds.
pub fn judge_effects(effects: &[f64], region: Region, confidence: f64) -> (Verdict, f64, f64, f64) {
    let (mean, lo, hi) = bounds(effects, confidence);
    let verdict = match decide(region, lo, hi) {
        Verdict::Inconclusive { .. } => {
            Verdict::Inconclusive { seeds: seeds_to_settle(effects, region, confidence) }
        }
        v => v,
    };
    (verdict, mean, lo, hi)
}

/// A number for the report: four decimals, or four significant digits when smaller.
pub fn num(x: f64) -> String {
    if x != 0.0 && x.abs() < 1e-3 { format!("{x:.3e}") } else { format!("{x:.4}") }
}
