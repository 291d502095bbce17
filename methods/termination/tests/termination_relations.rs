//! The relations of variance-trading-termination.txt's Table 1 and Fig. 10, played end to end
//! through `flicker run`'s playback on the shipped scenarios (scenarios/termination_*.ron) at
//! 32x18, one recorded frame after the cache's warm-up, over three seeds:
//!
//! - mean path length grows with the relative variance threshold t: in every seed, and in the
//!   log ratio over t = 0.01 .. 1 with a margin from the seeds;
//! - MSE minimisation's mean path length is below variance bounding's at absolute t = 0.01 in
//!   the paper's radiance unit (Table 1): reversed in the corridor, which the test asserts.
//!
//! Not asserted: the door's Table 1 relation and Fig. 10's FLIP relation (variance bounding at
//! relative t = 1 against area spread at c = 0.01). Over three seeds their 95% intervals hold
//! zero and the paper's effect alike, so asserting that no difference exists would pass for
//! almost any tracer. `flicker reproduce variance-trading-termination` judges the door's
//! relation over five seeds (claim `mse_shorter_than_vb_door`) and Fig. 10's in the corridor.
//!
//! At 32x18 the paper's 1% of primary vertices is 6 stored vertices a frame, too few to fill
//! the cache in its warm-up (a seed then measures an empty cache: zero-variance records let
//! variance bounding run every path to max depth). The test therefore stores 10% and warms up
//! for 24 frames; everything else is the shipped scenario's.
//!
//! Each relation holds over the seeds: the one-sided 95% bound (Student t, 2 degrees of freedom)
//! of the mean per-seed difference must lie above zero, so the margin comes from the spread
//! across seeds, not from one run.

use std::path::{Path, PathBuf};

use frame::frame_record::FrameRecord;
use playback::play::{RunOptions, run_spec};
use playback::scenario::{Overrides, RunSpec};

use testkit::relations::assert_positive;

const SEEDS: [u64; 3] = [3, 4, 5];

/// The door's records are a two-way draw at 32x18 (no record lit past the gap, or a few far too
/// bright: docs/lab/termination-paper-conditions.md), so its path lengths spread widely across
/// seeds: five seeds give its relation the power that three give the corridor's.
const DOOR_SEEDS: [u64; 5] = [3, 4, 5, 6, 7];

/// The scenario's methods named in `keep`, one recorded frame at 32x18: (method, path length,
/// FLIP) per seed.
fn play(scenario: &str, keep: &[&str], seed: u64) -> Vec<FrameRecord> {
    let file = Path::new(env!("CARGO_MANIFEST_DIR")).join("../..").join("scenarios").join(scenario);
    let tmp = tempfile::tempdir().unwrap();
    let dir = tmp.path().to_path_buf();
    let overrides = Overrides {
        frames: Some(1),
        resolution: Some((32, 18)),
        seed: Some(seed),
        out: Some(dir.join("run")),
        ..Default::default()
    };
    let mut spec = RunSpec::load(&file, &overrides).expect("scenario");
    spec.methods.retain(|m| keep.contains(&m.label().as_str()));
    for m in &mut spec.methods {
        if let Some(t) = m.spec.get_mut::<termination::TerminationSettings>() {
            t.store_probability = 0.1;
            t.warmup_frames = 24;
            // K = 4: the lavapipe time this test was sized for (K = 32, the default, costs
            // about 5 times the propagation); the Fig. 7 claims judge K = 32 against 4.
            t.samples_per_vertex = 4;
        }
    }
    assert_eq!(spec.methods.len(), keep.len(), "{scenario}: methods {keep:?}");
    let opts = RunOptions {
        scenario: PathBuf::from(&file),
        overrides,
        cache_dir: Some(dir.join("references")),
        progress: false,
    };
    let summary = run_spec(&spec, &opts).expect("run");
    summary.records
}

fn value(records: &[FrameRecord], method: &str, f: impl Fn(&FrameRecord) -> Option<f64>) -> f64 {
    let row =
        records.iter().find(|r| r.method == method).unwrap_or_else(|| panic!("no row of {method}"));
    f(row).unwrap_or_else(|| panic!("{method}: value missing"))
}

fn path_length(r: &FrameRecord) -> Option<f64> {
    r.stats.iter().find(|(k, _)| k == "path_length").map(|s| s.1)
}

fn path_length_relations(scenario: &str, seeds: &[u64], runs: &[Vec<FrameRecord>]) {
    let pl = |m: &str| runs.iter().map(|r| value(r, m, path_length)).collect::<Vec<f64>>();
    let (r001, r01, r1) = (pl("vb_rel_0.01"), pl("vb_rel_0.1"), pl("vb_rel_1"));
    // Grows with t in every seed: 6 of 6 paired comparisons (probability 1/64 if the order
    // were a coin toss).
    for s in 0..runs.len() {
        assert!(
            r001[s] < r01[s] && r01[s] < r1[s],
            "{scenario} seed {}: path length by relative t 0.01, 0.1, 1: {} {} {}",
            seeds[s],
            r001[s],
            r01[s],
            r1[s]
        );
    }
    // Across the decade range, by a margin from the spread over seeds: the path length grows
    // multiplicatively, and the seeds' caches differ in scale, so the log ratio.
    let log_ratio: Vec<f64> = r1.iter().zip(&r001).map(|(a, b)| (a / b).ln()).collect();
    assert_positive(&format!("{scenario}: ln(path length at relative t 1 / at 0.01)"), &log_ratio);
}

/// Per seed, `a`'s path length minus `b`'s.
fn path_length_difference(runs: &[Vec<FrameRecord>], a: &str, b: &str) -> Vec<f64> {
    runs.iter().map(|r| value(r, a, path_length) - value(r, b, path_length)).collect()
}

#[test]
fn door_relations() {
    let keep = ["vb_rel_0.01", "vb_rel_0.1", "vb_rel_1"];
    let runs: Vec<_> =
        DOOR_SEEDS.iter().map(|&s| play("termination_door_gap.ron", &keep, s)).collect();
    for (seed, r) in DOOR_SEEDS.iter().zip(&runs) {
        for m in keep {
            eprintln!("door seed {seed} {m}: path length {:.3}", value(r, m, path_length));
        }
    }
    path_length_relations("door", &DOOR_SEEDS, &runs);
}

#[test]
fn corridor_relations() {
    let keep = ["vb_0.01", "vb_rel_0.01", "vb_rel_0.1", "vb_rel_1", "mse_100"];
    let runs: Vec<_> = SEEDS.iter().map(|&s| play("termination_corridor.ron", &keep, s)).collect();
    for (seed, r) in SEEDS.iter().zip(&runs) {
        for m in keep {
            eprintln!("corridor seed {seed} {m}: path length {:.3}", value(r, m, path_length));
        }
    }
    path_length_relations("corridor", &SEEDS, &runs);
    // Table 1's relation (MSE minimisation shorter than variance bounding at absolute t = 0.01)
    // is reversed here (docs/lab/termination-relations.md): asserted as measured, MSE is longer.
    let d = path_length_difference(&runs, "mse_100", "vb_0.01");
    assert_positive("corridor: path length, MSE s 100 - variance bounding t 0.01", &d);
}
