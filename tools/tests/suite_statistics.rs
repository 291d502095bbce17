//! The suite's statistics on synthetic data: a relative gate judged by
//! `tools::suite::gate::judge`, the same path `flicker suite run` takes, on per-seed values
//! drawn from normal distributions with a deterministic RNG (SplitMix64 + Box-Muller).
//!
//! "Standard error" here is σ, the standard deviation of one seed's value (the error of one
//! measurement). Read as the standard error of the difference of two means, a true difference
//! of 3 of them cannot be caught 95% of the time while 95% of no-difference runs pass: any
//! one-sided test of a normal statistic would need its threshold both above 1.645 and below
//! 3 - 1.645 = 1.355 standard errors (and Welch's t, with estimated variances, does worse).

use std::collections::BTreeMap;

use scene::rng::SplitMix64;
use tools::suite::gate::judge;
use tools::suite::measurement::{CaseRuns, SeedRun};
use tools::suite::metric::Metric;
use tools::suite::spec::{Bound, Gate};
use tools::suite::window::Window;

const RUNS: usize = 200;

struct Normal(SplitMix64);

impl Normal {
    fn sample(&mut self, mean: f64, sigma: f64) -> f64 {
        // Box-Muller on two uniforms in (0, 1].
        let u = |r: &mut SplitMix64| ((r.next_u64() >> 11) as f64 + 1.0) / (1u64 << 53) as f64;
        let (u1, u2) = (u(&mut self.0), u(&mut self.0));
        mean + sigma * (-2.0 * u1.ln()).sqrt() * (2.0 * std::f64::consts::PI * u2).cos()
    }
}

/// One case of `seeds` seeds whose method "m" has FLIP `values[i]` on its one frame.
fn runs(values: &[f64]) -> CaseRuns {
    let seeds = values
        .iter()
        .enumerate()
        .map(|(i, &v)| {
            let metrics = BTreeMap::from([(Metric::Flip.name().to_string(), vec![Some(v)])]);
            SeedRun {
                seed: i as u64,
                methods: BTreeMap::from([("m".to_string(), metrics)]),
                ..Default::default()
            }
        })
        .collect();
    CaseRuns { frames: 1, events: Vec::new(), seeds }
}

fn gate(confidence: f64) -> Gate {
    Gate {
        metric: Metric::Flip,
        window: Window::Overall,
        bound: Bound::Relative { tolerance: 0.0 },
        confidence,
        cases: None,
        methods: None,
        entry: None,
    }
}

/// Share of `RUNS` synthetic runs the gate fails, the new mean `shift` above the baseline's.
fn fail_rate(rng: &mut Normal, gate: &Gate, seeds: usize, shift: f64) -> f64 {
    let (mean, sigma) = (0.3, 0.02);
    let failed = (0..RUNS)
        .filter(|_| {
            let base: Vec<f64> = (0..seeds).map(|_| rng.sample(mean, sigma)).collect();
            let new: Vec<f64> =
                (0..seeds).map(|_| rng.sample(mean + shift * sigma, sigma)).collect();
            !judge(gate, "case", "m", &runs(&new), Some(&runs(&base))).passed()
        })
        .count();
    failed as f64 / RUNS as f64
}

#[test]
fn three_standard_errors_are_caught_and_no_difference_passes() {
    let mut rng = Normal(SplitMix64::new(11));
    // 99% confidence, 6 seeds a side: expected power 0.98, expected false failures 1%.
    let g = gate(0.99);
    let caught = fail_rate(&mut rng, &g, 6, 3.0);
    let false_failures = fail_rate(&mut rng, &g, 6, 0.0);
    eprintln!("6 seeds, 99%: caught {caught:.3}, no difference failed {false_failures:.3}");
    assert!(
        caught >= 0.95,
        "a true difference of 3 σ was caught in {:.1}% of {RUNS} runs",
        caught * 100.0
    );
    assert!(
        false_failures <= 0.05,
        "with no difference {:.1}% of {RUNS} runs failed",
        false_failures * 100.0
    );
    // Improvements never fail a one-sided gate.
    assert_eq!(fail_rate(&mut rng, &g, 6, -3.0), 0.0);
}

#[test]
fn false_failures_match_the_stated_confidence() {
    // At 95% and 10 seeds a side about 5% of no-difference runs fail (binomial sd over 2000
    // runs: 0.5%): the p-values are calibrated, neither too eager nor too lax. With 3 seeds
    // Welch's df (estimated from two 3-value variances) makes the test conservative: fewer fail.
    let mut rng = Normal(SplitMix64::new(12));
    let g = gate(0.95);
    let rate = |rng: &mut Normal, seeds| {
        (0..10).map(|_| fail_rate(rng, &g, seeds, 0.0)).sum::<f64>() / 10.0
    };
    let (ten, three) = (rate(&mut rng, 10), rate(&mut rng, 3));
    eprintln!("95%: no difference failed {ten:.4} with 10 seeds, {three:.4} with 3");
    assert!((0.035..=0.065).contains(&ten), "false-failure rate {ten} at 95% confidence, 10 seeds");
    assert!(three <= 0.05, "false-failure rate {three} at 95% confidence, 3 seeds");
}

/// One case whose methods "a" and "b" have FLIP `a[i]` and `b[i]` for seed i.
fn two_methods(a: &[f64], b: &[f64]) -> CaseRuns {
    let seeds = a
        .iter()
        .zip(b)
        .enumerate()
        .map(|(i, (&x, &y))| {
            let one = |v: f64| BTreeMap::from([(Metric::Flip.name().to_string(), vec![Some(v)])]);
            SeedRun {
                seed: i as u64,
                methods: BTreeMap::from([("a".to_string(), one(x)), ("b".to_string(), one(y))]),
                ..Default::default()
            }
        })
        .collect();
    CaseRuns { frames: 1, events: Vec::new(), seeds }
}

#[test]
fn relation_gates_pass_only_when_the_method_is_better_with_confidence() {
    let gate = Gate { bound: Bound::Better { than: "b".into() }, ..gate(0.95) };
    // Per seed, a is clearly below b (lower FLIP is better), with a spread.
    let better = two_methods(&[0.30, 0.31, 0.29, 0.305], &[0.35, 0.37, 0.34, 0.36]);
    assert!(judge(&gate, "case", "a", &better, None).passed());
    // Equal on average, or worse: not shown, so the gate fails.
    let mixed = two_methods(&[0.30, 0.36, 0.29, 0.37], &[0.33, 0.33, 0.33, 0.33]);
    assert!(!judge(&gate, "case", "a", &mixed, None).passed());
    assert!(!judge(&gate, "case", "b", &better, None).passed());
    // Synthetic runs: a true paired advantage of 3 σ of a seed's difference, 6 seeds, is shown
    // in at least 95% of 200 runs; no advantage passes in at most 5% + noise.
    let mut rng = Normal(SplitMix64::new(17));
    let mut rate = |shift: f64| {
        let passed = (0..RUNS)
            .filter(|_| {
                let b: Vec<f64> = (0..6).map(|_| rng.sample(0.3, 0.02)).collect();
                let a: Vec<f64> =
                    b.iter().map(|v| v - shift * 0.02 + rng.sample(0.0, 0.02)).collect();
                judge(&gate, "case", "a", &two_methods(&a, &b), None).passed()
            })
            .count();
        passed as f64 / RUNS as f64
    };
    let (caught, false_pass) = (rate(3.0), rate(0.0));
    eprintln!(
        "relation gate: a true 3σ advantage shown in {caught:.3} of runs, no advantage passes in {false_pass:.3}"
    );
    assert!(caught >= 0.95, "{caught}");
    assert!(false_pass <= 0.08, "{false_pass}");
}
