//! Judging one claim on per-seed values, with three outcomes and a margin that matters.
//!
//! Every comparison becomes a per-seed effect (a difference, a value, a ratio, a log ratio)
//! and the interval of its mean between the one-sided `confidence` lower and upper bounds (the
//! (2·confidence − 1) two-sided interval, as in the two one-sided tests of equivalence). The
//! claim's smallest effect that matters (δ, `claims::Effect`) turns the paper's claim into a
//! region of effects: a relation (`Below`, `NotAbove`, `Rises`, `LogRatio` below a factor) is
//! the side beyond an edge; a value (`Value`, `Ratio`, `Difference`, `LogRatio` near a factor) is the
//! band within δ of the paper's number. Then (`decide`):
//!
//! - *reproduced*: the interval lies inside the paper's region;
//! - *not reproduced*: the interval lies outside it (a relation: the effect goes the other way
//!   or is too small to matter; a value: it differs from the paper's by more than δ);
//! - *inconclusive*: the interval holds an edge, with the seeds that would likely settle it.
//!
//! Data that cannot be judged at all (fewer than two seeds, different seeds for the two
//! methods, a value that is not a number, a ratio's zero) are *not comparable*, with the
//! reason; so are claims the lab declares it does not measure.

use super::claims::{Comparison, Effect};
use super::log_ratio::RatioExpectation;
use crate::suite::student_t;
use crate::suite::welch::Sample;
use crate::suite::window::Window;

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

fn mean(v: &[f64]) -> f64 {
    Sample::of(v).mean
}

/// `a` below `b` (labelled `names`) on the paired per-seed differences a − b: by at least δ
/// (from `effect`; relative: of b's mean), or with `no_worse` not above it by δ or more.
fn paired_below(
    a: Vec<f64>,
    b: Vec<f64>,
    names: (&str, &str),
    effect: &Effect,
    no_worse: bool,
    confidence: f64,
) -> Judged {
    if let Some(j) = unpaired(&a, &b, names) {
        return j;
    }
    let diffs: Vec<f64> = a.iter().zip(&b).map(|(x, y)| x - y).collect();
    let delta = effect.margin(mean(&b));
    let region = Region::Below { edge: if no_worse { delta } else { -delta } };
    let (verdict, d, lo, hi) = judge_effects(&diffs, region, confidence);
    let flicker = format!(
        "{} {} vs {} {}; difference {} [{}, {}], margin {} ({} seeds)",
        names.0,
        num(mean(&a)),
        names.1,
        num(mean(&b)),
        num(d),
        num(lo),
        num(hi),
        num(delta),
        diffs.len()
    );
    Judged { flicker, verdict, values: [a, b].concat() }
}

/// Why two methods' per-seed values cannot be paired, or why one is not a number.
fn unpaired(a: &[f64], b: &[f64], names: (&str, &str)) -> Option<Judged> {
    let values = [a, b].concat();
    if a.len() != b.len() || a.len() < 2 {
        return Some(not_comparable(
            format!(
                "{} and {} seed(s); a paired interval needs the same seeds, at least 2",
                a.len(),
                b.len()
            ),
            values,
        ));
    }
    let bad = a.iter().map(|v| (names.0, v)).chain(b.iter().map(|v| (names.1, v)));
    if let Some((m, v)) = bad.into_iter().find(|(_, v)| !v.is_finite()) {
        return Some(not_comparable(format!("{m} is {v} in a seed; expected a number"), values));
    }
    None
}

/// A value's per-seed `effects` against the paper's `value` ± δ; `what` names the effect.
fn band(effects: Vec<f64>, what: &str, value: f64, effect: &Effect, confidence: f64) -> Judged {
    if effects.len() < 2 {
        return not_comparable(
            format!("{} seed(s); an interval needs at least 2", effects.len()),
            effects,
        );
    }
    if let Some(v) = effects.iter().find(|v| !v.is_finite()) {
        return not_comparable(format!("{what} is {v} in a seed; expected a number"), effects);
    }
    let delta = effect.margin(value);
    let region = Region::Within { low: value - delta, high: value + delta };
    let (verdict, m, lo, hi) = judge_effects(&effects, region, confidence);
    let flicker = format!(
        "{what} {} [{}, {}], paper {value} ± {} ({} seeds)",
        num(m),
        num(lo),
        num(hi),
        num(delta),
        effects.len()
    );
    Judged { flicker, verdict, values: effects }
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

/// One row of the rules' table (docs/reproduce.md, "Comparisons and verdicts").
#[derive(Clone, Debug, PartialEq)]
pub struct Rule {
    /// The comparison as a claims file writes it.
    pub comparison: &'static str,
    /// The per-seed effect whose interval is judged.
    pub effect: &'static str,
    /// The paper's region, in terms of δ.
    pub region: &'static str,
    pub reproduced: &'static str,
    pub not_reproduced: &'static str,
    pub inconclusive: &'static str,
}

const RELATION: (&str, &str, &str) = (
    "upper bound < edge",
    "lower bound > edge (the other way, or too small to matter)",
    "the interval holds the edge",
);
const VALUE: (&str, &str, &str) = (
    "interval inside the band",
    "interval outside the band",
    "the interval holds an edge of the band",
);

/// Every comparison's rule: what is judged and when it is reproduced, not reproduced or
/// inconclusive. `judge` follows it (each comparison's `Region`, then `decide`); the docs'
/// table is this list (tests/reproduce_docs.rs).
pub fn rules() -> Vec<Rule> {
    let rule = |comparison,
                effect,
                region,
                (r, n, i): (&'static str, &'static str, &'static str)| {
        Rule { comparison, effect, region, reproduced: r, not_reproduced: n, inconclusive: i }
    };
    vec![
        rule(
            "Below(method: A, than: B)",
            "A − B",
            "below the edge −δ (relative: δ = r · B's mean)",
            RELATION,
        ),
        rule(
            "NotAbove(method: A, than: B)",
            "A − B",
            "below the edge +δ (relative: δ = r · B's mean)",
            RELATION,
        ),
        rule(
            "Rises(method: A, from: W)",
            "A over W − A over the claim's window",
            "below the edge −δ (relative: of the claim window's mean)",
            RELATION,
        ),
        rule("Value(method: A, value: v)", "A", "the band v ± δ (relative: δ = r · v)", VALUE),
        rule(
            "Ratio(method: A, to: B, value: v)",
            "A / B",
            "the band v ± δ (relative: δ = r · v)",
            VALUE,
        ),
        rule(
            "Difference(method: A, to: B, value: v)",
            "A − B",
            "the band v ± δ (relative: δ = r · v)",
            VALUE,
        ),
        rule(
            "LogRatio(method: A, to: B, expect: Below(f))",
            "ln(A / B)",
            "below the edge ln(f − δ) (relative: ln(f · (1 − r)))",
            RELATION,
        ),
        rule(
            "LogRatio(method: A, to: B, expect: Near(v))",
            "ln(A / B)",
            "the band ln(v − δ) .. ln(v + δ) (relative: δ = r · v)",
            VALUE,
        ),
    ]
}

/// Judges `comparison`, with the claim's smallest effect that matters, by `per_seed(method,
/// window)`: one value per seed (the same seeds, in the same order, for every method) over
/// `window` (`None`: the claim's), or why there is none.
pub fn judge(
    comparison: &Comparison,
    effect: &Effect,
    per_seed: &dyn Fn(&str, Option<&Window>) -> Result<Vec<f64>, String>,
) -> Judged {
    let values = |m: &str| per_seed(m, None).map_err(|e| format!("{m}: {e}"));
    let none = |e: String| not_comparable(e, Vec::new());
    match comparison {
        Comparison::NotComparable { reason, .. } => none(reason.clone()),
        Comparison::Below { method, than, confidence } => match (values(method), values(than)) {
            (Ok(a), Ok(b)) => paired_below(a, b, (method, than), effect, false, *confidence),
            (Err(e), _) | (_, Err(e)) => none(e),
        },
        Comparison::NotAbove { method, than, confidence } => match (values(method), values(than)) {
            (Ok(a), Ok(b)) => paired_below(a, b, (method, than), effect, true, *confidence),
            (Err(e), _) | (_, Err(e)) => none(e),
        },
        // Rising: the earlier window's values below the claim's window's, paired per seed.
        Comparison::Rises { method, from, confidence } => {
            let before = per_seed(method, Some(from))
                .map_err(|e| format!("{method} over {}: {e}", from.name()));
            match (before, values(method)) {
                (Ok(a), Ok(b)) => {
                    let before = format!("{method} over {}", from.name());
                    paired_below(a, b, (&before, "the claim's window"), effect, false, *confidence)
                }
                (Err(e), _) | (_, Err(e)) => none(e),
            }
        }
        Comparison::Value { method, value, confidence } => match values(method) {
            Ok(v) => band(v, method, *value, effect, *confidence),
            Err(e) => none(e),
        },
        Comparison::Ratio { method, to, value, confidence } => {
            let per_seed = |a: Vec<f64>, b: Vec<f64>| {
                if b.contains(&0.0) {
                    return Err(format!("{to} is 0 in a seed; no ratio"));
                }
                Ok(a.iter().zip(&b).map(|(x, y)| x / y).collect())
            };
            match paired(values(method), values(to), "a ratio", per_seed) {
                Ok(r) => band(r, &format!("{method} / {to}"), *value, effect, *confidence),
                Err(e) => none(e),
            }
        }
        Comparison::LogRatio { method, to, expect, confidence } => {
            match (values(method), values(to)) {
                (Ok(a), Ok(b)) => {
                    super::log_ratio::judge(a, b, (method, to), expect, effect, *confidence)
                }
                (Err(e), _) | (_, Err(e)) => none(e),
            }
        }
        Comparison::Difference { method, to, value, confidence } => {
            let per_seed =
                |a: Vec<f64>, b: Vec<f64>| Ok(a.iter().zip(&b).map(|(x, y)| x - y).collect());
            match paired(values(method), values(to), "a difference", per_seed) {
                Ok(d) => band(d, &format!("{method} − {to}"), *value, effect, *confidence),
                Err(e) => none(e),
            }
        }
    }
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
