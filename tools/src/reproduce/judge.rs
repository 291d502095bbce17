//! Judging one claim on per-seed values, with three outcomes and a margin that matters.
//!
//! Every comparison becomes a per-seed effect (a difference, a value, a ratio, a log ratio)
//! and the interval of its mean between the one-sided `confidence` lower and upper bounds (the
//! (2·confidence − 1) two-sided interval, as in the two one-sided tests of equivalence). The
//! claim's smallest effect that matters (δ, `effect::Effect`) turns the paper's claim into a
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

use super::claims::Comparison;
use super::effect::Effect;
use super::verdict::{Judged, Region, judge_effects, not_comparable, num};
use crate::suite::welch::Sample;
use crate::suite::window::Window;

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
