//! The three outcomes with a margin that matters, on hand-made per-seed values: every outcome
//! of every comparison kind, among them an interval across zero (inconclusive), a tight
//! interval around zero inside the margin (not reproduced) and an effect on the paper's side
//! smaller than the margin (not reproduced, where a bare sign test says reproduced).
//!
//! Bounds by hand: three seeds, one-sided 95%, t(0.95, 2) = 2.92; a spread of 0.01 (values
//! x − 0.01, x, x + 0.01) has standard error 0.00577 and bounds x ± 0.0169.

use tools::reproduce::log_ratio::RatioExpectation;
use tools::reproduce::verdict::{Region, decide, seeds_to_settle};
use tools::reproduce::{Comparison, Effect, Judged, Verdict, judge};
use tools::suite::window::Window;

const ABS: Effect = Effect::Absolute(0.05);

/// Per-seed values of methods "a" and "b" (and "a" over the window before event 0: `before`).
fn run(a: &[f64], b: &[f64]) -> impl Fn(&str, Option<&Window>) -> Result<Vec<f64>, String> {
    let (a, b) = (a.to_vec(), b.to_vec());
    move |m, w| match (m, w) {
        ("a", None) => Ok(a.clone()),
        ("b", None) | ("a", Some(_)) => Ok(b.clone()),
        _ => Err("not in the run".into()),
    }
}

/// `b` with `diffs` added seed by seed (a = b + d).
fn plus(b: &[f64], diffs: &[f64]) -> Vec<f64> {
    b.iter().zip(diffs).map(|(x, d)| x + d).collect()
}

fn is_inconclusive(j: &Judged) -> bool {
    matches!(j.verdict, Verdict::Inconclusive { .. })
}

const B: [f64; 3] = [0.40, 0.42, 0.41];

fn below() -> Comparison {
    Comparison::Below { method: "a".into(), than: "b".into(), confidence: 0.95 }
}

#[test]
fn below_has_every_outcome() {
    let j = |diffs: &[f64], e: &Effect| judge(&below(), e, &run(&plus(&B, diffs), &B));
    // Below by 0.10 ± 0.0169, beyond the margin 0.05: reproduced.
    let r = j(&[-0.10, -0.11, -0.09], &ABS);
    assert_eq!(r.verdict, Verdict::Reproduced, "{}", r.flicker);
    assert!(r.flicker.starts_with("a 0.3100 vs b 0.4100; difference -0.1000"), "{}", r.flicker);
    // The other way: not reproduced.
    assert_eq!(j(&[0.10, 0.11, 0.09], &ABS).verdict, Verdict::NotReproduced);
    // An interval across zero (−0.0067, bounds −0.083 and +0.069, holding the edge −0.05):
    // inconclusive, where the sign test called it refuted.
    let across = j(&[-0.05, 0.04, -0.01], &ABS);
    assert!(is_inconclusive(&across), "{:?}: {}", across.verdict, across.flicker);
    // A tight interval around zero, inside ±0.05: equivalence, not reproduced.
    let zero = j(&[-0.001, 0.0, 0.001], &ABS);
    assert_eq!(zero.verdict, Verdict::NotReproduced, "{}", zero.flicker);
    // On the paper's side but smaller than the margin (−0.010 ± 0.0017, upper bound below 0):
    // not reproduced, where the sign test called it reproduced.
    let small = j(&[-0.011, -0.010, -0.009], &ABS);
    assert_eq!(small.verdict, Verdict::NotReproduced, "{}", small.flicker);
    // A relative margin is a share of b's mean (0.41): 5% is 0.0205, so −0.03 ± 0.0017 is
    // reproduced and −0.015 ± 0.0017 is not.
    let rel = Effect::Relative(0.05);
    assert_eq!(j(&[-0.031, -0.030, -0.029], &rel).verdict, Verdict::Reproduced);
    assert_eq!(j(&[-0.016, -0.015, -0.014], &rel).verdict, Verdict::NotReproduced);
}

/// The interval across zero above: mean −0.00667, sd 0.04509, 0.04333 from the edge −0.05.
/// (t(0.95, n−1) + t(0.8, n−1)) / √n ≤ 0.04333 / 0.04509 = 0.961 first at n = 9 (tables: n =
/// 8: (1.895 + 0.896) / 2.828 = 0.987; n = 9: (1.860 + 0.889) / 3 = 0.916).
#[test]
fn inconclusive_names_the_seeds_that_would_likely_settle_it() {
    let across = judge(&below(), &ABS, &run(&plus(&B, &[-0.05, 0.04, -0.01]), &B));
    assert_eq!(across.verdict, Verdict::Inconclusive { seeds: Some(9) }, "{}", across.flicker);
    assert!(across.verdict.text().contains("about 9 seeds"));
    // A mean on the edge: no number of seeds settles it.
    let edge = Region::Below { edge: -0.05 };
    assert_eq!(seeds_to_settle(&[-0.06, -0.05, -0.04], edge, 0.95), None);
    // A band's nearest edge counts: mean 2.0 in 1.76 ± 0.25 is 0.01 from the edge 2.01.
    let band = Region::Within { low: 1.51, high: 2.01 };
    let n = seeds_to_settle(&[1.99, 2.0, 2.01], band, 0.95).unwrap();
    assert!((4..=100).contains(&n), "{n}");
}

#[test]
fn not_above_has_every_outcome() {
    let c = Comparison::NotAbove { method: "a".into(), than: "b".into(), confidence: 0.95 };
    let j = |diffs: &[f64]| judge(&c, &ABS, &run(&plus(&B, diffs), &B));
    // Equal within ±0.0169, under the edge +0.05: reproduced (no worse).
    assert_eq!(j(&[0.01, 0.0, -0.01]).verdict, Verdict::Reproduced);
    // Worse by 0.10 ± 0.0169: not reproduced.
    assert_eq!(j(&[0.10, 0.11, 0.09]).verdict, Verdict::NotReproduced);
    // 0.04, bounds −0.037 and +0.117, holding +0.05: inconclusive.
    assert!(is_inconclusive(&j(&[0.0, 0.09, 0.03])));
}

#[test]
fn rises_has_every_outcome() {
    let c = Comparison::Rises {
        method: "a".into(),
        from: Window::Before { event: 0 },
        confidence: 0.95,
    };
    // `run` gives "a" over the earlier window b's values; over the claim's window a's.
    let j = |before: &[f64], after: &[f64]| judge(&c, &ABS, &run(after, before));
    let before = [0.10, 0.12, 0.11];
    assert_eq!(j(&before, &[0.30, 0.33, 0.31]).verdict, Verdict::Reproduced);
    assert_eq!(j(&[0.30, 0.33, 0.31], &before).verdict, Verdict::NotReproduced);
    // A rise of 0.001 ± 0.0017: smaller than the margin, not reproduced.
    assert_eq!(j(&before, &[0.100, 0.121, 0.112]).verdict, Verdict::NotReproduced);
    // Differences −0.1, +0.05, −0.08 (mean −0.043, bounds −0.180 and +0.094): inconclusive.
    assert!(is_inconclusive(&j(&[0.10, 0.20, 0.12], &[0.20, 0.15, 0.20])));
}

#[test]
fn value_has_every_outcome() {
    let c = |value| Comparison::Value { method: "a".into(), value, confidence: 0.95 };
    let a = [1.99, 2.00, 2.01];
    let j = |value, e: &Effect| judge(&c(value), e, &run(&a, &B));
    let quarter = Effect::Absolute(0.25);
    // 2.0 ± 0.0169 inside 1.98 ± 0.25: reproduced; outside 1.0 ± 0.25: not reproduced.
    assert_eq!(j(1.98, &quarter).verdict, Verdict::Reproduced);
    assert_eq!(j(1.0, &quarter).verdict, Verdict::NotReproduced);
    // The band's edge 2.01 inside the interval: inconclusive.
    assert!(is_inconclusive(&j(1.76, &quarter)));
    // A relative band: 5% of 2.0 is 0.1, so 2.0 ± 0.1 holds [1.983, 2.017]; 1% of 2.0 is
    // 0.02, whose edges 1.98 and 2.02 the interval does not reach either: reproduced too; 0.5%
    // (edges 1.99 and 2.01) lies inside the interval: inconclusive.
    assert_eq!(j(2.0, &Effect::Relative(0.05)).verdict, Verdict::Reproduced);
    assert_eq!(j(2.0, &Effect::Relative(0.01)).verdict, Verdict::Reproduced);
    assert!(is_inconclusive(&j(2.0, &Effect::Relative(0.005))));
    // A spread wider than the band holds both edges: inconclusive.
    let wide = judge(&c(2.0), &quarter, &run(&[1.5, 2.0, 2.5], &B));
    assert!(is_inconclusive(&wide), "{}", wide.flicker);
}

#[test]
fn ratio_has_every_outcome() {
    let c =
        |value| Comparison::Ratio { method: "a".into(), to: "b".into(), value, confidence: 0.95 };
    // Ratios 2.00, 2.01, 1.99 at values that differ threefold between seeds.
    let (a, b) = ([2.0, 4.02, 5.97], [1.0, 2.0, 3.0]);
    let j = |value, d| judge(&c(value), &Effect::Absolute(d), &run(&a, &b));
    assert_eq!(j(2.0, 0.1).verdict, Verdict::Reproduced);
    assert_eq!(j(1.5, 0.1).verdict, Verdict::NotReproduced);
    // 2.1 ± 0.1: the edge 2.0 inside [1.983, 2.017].
    assert!(is_inconclusive(&j(2.1, 0.1)));
    let zero = judge(&c(2.0), &ABS, &run(&a, &[1.0, 0.0, 3.0]));
    assert!(matches!(zero.verdict, Verdict::NotComparable(ref w) if w.contains("b is 0")));
}

#[test]
fn difference_has_every_outcome() {
    let c = |value| Comparison::Difference {
        method: "a".into(),
        to: "b".into(),
        value,
        confidence: 0.95,
    };
    // a − b = 0.29, 0.30, 0.31 dB: bounds 0.2831 and 0.3169.
    let (a, b) = ([47.85, 47.86, 47.87], [47.56, 47.56, 47.56]);
    let j = |value, d| judge(&c(value), &Effect::Absolute(d), &run(&a, &b));
    assert_eq!(j(0.3, 0.1).verdict, Verdict::Reproduced);
    assert_eq!(j(1.76, 0.1).verdict, Verdict::NotReproduced);
    // The sign matters: b − a is −0.30.
    assert_eq!(j(-0.3, 0.1).verdict, Verdict::NotReproduced);
    // 0.4 ± 0.09: the edge 0.31 inside the interval.
    assert!(is_inconclusive(&j(0.4, 0.09)));
}

#[test]
fn log_ratio_has_every_outcome() {
    let c = |expect| Comparison::LogRatio {
        method: "a".into(),
        to: "b".into(),
        expect,
        confidence: 0.95,
    };
    let b = [0.01, 0.1, 1.0];
    let j = |ratios: [f64; 3], expect| {
        let a: Vec<f64> = b.iter().zip(ratios).map(|(x, r)| x * r).collect();
        judge(&c(expect), &Effect::Relative(0.05), &run(&a, &b))
    };
    let one = || RatioExpectation::Below(1.0);
    // Half, at values a hundredfold apart: reproduced.
    assert_eq!(j([0.5, 0.52, 0.48], one()).verdict, Verdict::Reproduced);
    // The other way: not reproduced.
    assert_eq!(j([1.5, 1.6, 1.55], one()).verdict, Verdict::NotReproduced);
    // Around 1 within ±1%: equivalence, not reproduced.
    assert_eq!(j([1.0, 1.01, 0.99], one()).verdict, Verdict::NotReproduced);
    // Below 1 by 1.5% (upper bound under 1), less than the 5% margin: not reproduced.
    let small = j([0.98, 0.99, 0.985], one());
    assert_eq!(small.verdict, Verdict::NotReproduced, "{}", small.flicker);
    // Across 1: inconclusive.
    assert!(is_inconclusive(&j([0.7, 1.2, 0.9], one())));
    // Near 3 (± 5%: 2.85 .. 3.15).
    let near = || RatioExpectation::Near(3.0);
    assert_eq!(j([2.99, 3.0, 3.01], near()).verdict, Verdict::Reproduced);
    assert_eq!(j([2.0, 2.1, 2.05], near()).verdict, Verdict::NotReproduced);
    assert!(is_inconclusive(&j([2.9, 3.2, 2.8], near())));
}

#[test]
fn data_that_cannot_be_judged_are_not_comparable_with_the_reason() {
    let not = |j: Judged, why: &str| {
        assert!(
            matches!(j.verdict, Verdict::NotComparable(ref w) if w.contains(why)),
            "{:?} (expected '{why}')",
            j.verdict
        )
    };
    not(judge(&below(), &ABS, &run(&[0.3], &[0.4])), "at least 2");
    not(judge(&below(), &ABS, &run(&[0.3, 0.3], &[0.4])), "same seeds");
    not(judge(&below(), &ABS, &run(&[0.3, f64::NAN], &[0.4, 0.4])), "a is NaN");
    let missing = Comparison::Below { method: "a".into(), than: "z".into(), confidence: 0.95 };
    not(judge(&missing, &ABS, &run(&[0.3, 0.3], &[0.4, 0.4])), "z: not in the run");
    let declared = Comparison::NotComparable { methods: vec![], reason: "needs ms".into() };
    let j = judge(&declared, &ABS, &run(&[0.3, 0.3], &[0.4, 0.4]));
    assert_eq!(j.verdict, Verdict::NotComparable("needs ms".into()));
    assert_eq!(j.flicker, "not measured");
}

/// The rule itself, at its edges: strictly beyond an edge decides.
#[test]
fn the_rule_decides_at_the_edges() {
    let below = Region::Below { edge: -0.05 };
    assert_eq!(decide(below, -0.2, -0.06), Verdict::Reproduced);
    assert_eq!(decide(below, -0.04, 0.3), Verdict::NotReproduced);
    assert!(matches!(decide(below, -0.06, -0.04), Verdict::Inconclusive { .. }));
    let band = Region::Within { low: 1.0, high: 2.0 };
    assert_eq!(decide(band, 1.0, 2.0), Verdict::Reproduced);
    assert_eq!(decide(band, 2.1, 2.3), Verdict::NotReproduced);
    assert_eq!(decide(band, 0.1, 0.9), Verdict::NotReproduced);
    assert!(matches!(decide(band, 0.5, 2.5), Verdict::Inconclusive { .. }));
}
