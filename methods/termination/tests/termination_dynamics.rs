//! Beyond variance-trading-termination.txt (static scenes only): how its cache follows a flash,
//! how termination moves meanwhile, and where a rule fails (its Fig. 12, glossy bias). Played
//! end to end through `flicker run`'s playback on the shipped scenarios at 32x18 over three
//! seeds, with the settings of termination_relations.rs (10% of primary vertices stored, 24
//! warm-up frames, 8 before the flash: 1% fills too few records at this size).
//!
//! A record's moments are running means of its vertex estimates, exponential with weight
//! 1/max_vertices once full, and a record receives at most 4 estimates a frame (its 4 stored
//! vertices). After the flash the new estimates are at least the steady value in expectation
//! (they read records that still remember the flash), so the excess of the cache value over
//! its pre-flash level can shrink per frame by at most the factor (1 - 1/max_vertices)^4:
//! 0.939 for the default 64, 0.772 for 16. Measured: it shrinks much more slowly, because
//! propagation is a feedback loop (a record's estimates read its neighbours' records).
//!
//! Each relation holds over the seeds with a one-sided 95% Student-t bound of the mean per-seed
//! value (testkit::relations::assert_positive), so its margin comes from the spread across seeds.

use std::path::{Path, PathBuf};

use frame::frame_record::FrameRecord;
use playback::play::{RunOptions, run_spec};
use playback::scenario::{Overrides, RunSpec};
use sim::ReferenceFrames;

use testkit::relations::assert_positive;

const SEEDS: [u64; 3] = [3, 4, 5];

/// The scenario's methods named in `keep` at 32x18 for `frames` frames; `edit` changes the spec
/// (references, events).
fn play(
    scenario: &str,
    keep: &[&str],
    seed: u64,
    frames: u32,
    tag: &str,
    edit: impl Fn(&mut RunSpec),
) -> Vec<FrameRecord> {
    let file = Path::new(env!("CARGO_MANIFEST_DIR")).join("../..").join("scenarios").join(scenario);
    let tmp =
        tempfile::Builder::new().prefix(&format!("termination-dynamics-{tag}-")).tempdir().unwrap();
    let dir = tmp.path().to_path_buf();
    let overrides = Overrides {
        frames: Some(frames),
        resolution: Some((32, 18)),
        seed: Some(seed),
        out: Some(dir.join("run")),
        ..Default::default()
    };
    let mut spec = RunSpec::load(&file, &overrides).expect("scenario");
    spec.methods.retain(|m| keep.contains(&m.label().as_str()));
    assert_eq!(spec.methods.len(), keep.len(), "{scenario}: methods {keep:?}");
    for m in &mut spec.methods {
        if let Some(t) = m.spec.get_mut::<termination::TerminationSettings>() {
            t.store_probability = 0.1;
            t.warmup_frames = 24;
            // K = 4: the lavapipe time this test was sized for (K = 32, the default, costs
            // about 5 times the propagation); the Fig. 7 claims judge K = 32 against 4.
            t.samples_per_vertex = 4;
        }
    }
    edit(&mut spec);
    let opts = RunOptions {
        scenario: PathBuf::from(&file),
        overrides,
        cache_dir: Some(dir.join("references")),
        progress: false,
    };
    let summary = run_spec(&spec, &opts).expect("run");
    summary.records
}

/// `stat` of `method` per frame.
fn series(records: &[FrameRecord], method: &str, stat: &str) -> Vec<f64> {
    let mut rows: Vec<&FrameRecord> = records.iter().filter(|r| r.method == method).collect();
    rows.sort_by_key(|r| r.frame);
    rows.iter()
        .map(|r| {
            r.stats
                .iter()
                .find(|(k, _)| k == stat)
                .unwrap_or_else(|| panic!("{method}: no {stat}"))
                .1
        })
        .collect()
}

fn mean(v: &[f64]) -> f64 {
    v.iter().sum::<f64>() / v.len() as f64
}

/// The flash of termination_flash_corridor.ron: five times the light for frames 12..=15.
const FLASH: (usize, usize) = (12, 16);
/// Frames after the flash ends over which the per-frame forgetting factor is measured.
const DECAY_FRAMES: usize = 8;
/// The last frame looked at.
const LAST: usize = FLASH.1 + DECAY_FRAMES;
/// Warm-up frames of these runs: the flash comes 12 frames later, so the records are long
/// filled; fewer than termination_relations.rs's 24 keeps the four runs a seed short.
const WARMUP: u32 = 8;

#[test]
fn cache_follows_a_flash_and_forgets_it_slower_than_its_memory() {
    // Every rule of one cache setting sees the same cache (the cache's passes do not depend on
    // the rule), so one rule per memory: MSE minimisation (default 64 estimates) and variance
    // bounding with 16. Each seed is played with the flash and without it (the control, the
    // scenario's events removed): both are the same run up to frame 12, and the control takes
    // out the records' own drift after the warm-up (a record's count grows from the warm-up's
    // 4 estimates to max_vertices over the first frames, and its estimates settle meanwhile).
    let keep = ["mse_100", "vb_rel_1_fast"];
    let setup = |s: &mut RunSpec| {
        s.scenario.reference.frames = ReferenceFrames::None;
        for m in &mut s.methods {
            if let Some(t) = m.spec.get_mut::<termination::TerminationSettings>() {
                t.warmup_frames = WARMUP;
            }
        }
    };
    let frames = LAST as u32 + 1;
    let flashed: Vec<_> = SEEDS
        .iter()
        .map(|&s| play("termination_flash_corridor.ron", &keep, s, frames, "flash", setup))
        .collect();
    let control: Vec<_> = SEEDS
        .iter()
        .map(|&s| {
            play("termination_flash_corridor.ron", &keep, s, frames, "control", |spec| {
                setup(spec);
                spec.scenario.events.clear();
            })
        })
        .collect();
    // Per seed and memory, against the control: the cache value's and variance's rise at the
    // flash's last frame, the per-frame factor of their excess after it.
    let mut rise = [vec![], vec![]];
    let mut factor = [vec![], vec![]];
    let mut variance_rise = [vec![], vec![]];
    let mut variance_factor = [vec![], vec![]];
    let mut mse_length_change = vec![];
    for ((seed, f), c) in SEEDS.iter().zip(&flashed).zip(&control) {
        for (i, m) in keep.iter().enumerate() {
            let (value, var, len) = (
                series(f, m, "cache_mean"),
                series(f, m, "cache_variance"),
                series(f, m, "path_length"),
            );
            let (value_c, var_c, len_c) = (
                series(c, m, "cache_mean"),
                series(c, m, "cache_variance"),
                series(c, m, "path_length"),
            );
            eprintln!(
                "seed {seed} {m}, flash: cache mean {value:.3?}\n  variance {var:.3?}\n  path length {len:.3?}"
            );
            eprintln!(
                "seed {seed} {m}, control: cache mean {value_c:.3?}\n  variance {var_c:.3?}\n  path length {len_c:.3?}"
            );
            let excess = |a: &[f64], b: &[f64], f: usize| a[f] - b[f];
            let last = FLASH.1 - 1;
            rise[i].push((value[last] / value_c[last]).ln());
            variance_rise[i].push((var[last] / var_c[last]).ln());
            let per_frame = |a: &[f64], b: &[f64]| {
                (excess(a, b, LAST) / excess(a, b, FLASH.1)).powf(1.0 / DECAY_FRAMES as f64)
            };
            factor[i].push(per_frame(&value, &value_c));
            variance_factor[i].push(per_frame(&var, &var_c));
            if i == 0 {
                mse_length_change
                    .push(mean(&len[FLASH.1..FLASH.1 + 4]) - mean(&len_c[FLASH.1..FLASH.1 + 4]));
            }
        }
    }
    eprintln!(
        "rise {rise:.3?}\nvariance rise {variance_rise:.3?}\nfactor {factor:.3?}\nvariance factor {variance_factor:.3?}\nMSE path length change {mse_length_change:.3?}"
    );
    for (i, m) in keep.iter().enumerate() {
        assert_positive(
            &format!("{m}: ln(cache value at the flash's last frame / control)"),
            &rise[i],
        );
        assert_positive(
            &format!("{m}: ln(cache variance at the flash's last frame / control)"),
            &variance_rise[i],
        );
    }
    // The shorter memory takes up more of the flash in its 4 frames ...
    let d: Vec<f64> = rise[1].iter().zip(&rise[0]).map(|(a, b)| a - b).collect();
    assert_positive("rise of the cache value, 16 minus 64 estimates", &d);
    // ... and forgets the flash's variance faster.
    let d: Vec<f64> =
        variance_factor[0].iter().zip(&variance_factor[1]).map(|(a, b)| a - b).collect();
    assert_positive("per-frame forgetting factor of the cache variance, 64 minus 16 estimates", &d);
    // The cache keeps more of the flash than its memory alone would ((1 - 1/n)^4 a frame, the
    // bound above): a record's new estimates read neighbouring records that still hold the
    // flash (propagation is a feedback loop through the scene's interreflection), so the
    // excess outlives the running mean. Measured: docs/lab/termination-dynamics.md.
    for (i, n) in [64.0f64, 16.0].into_iter().enumerate() {
        let bound = (1.0 - 1.0 / n).powi(4);
        let d: Vec<f64> = factor[i].iter().map(|f| f - bound).collect();
        assert_positive(
            &format!(
                "{}: per-frame forgetting factor of the cache value minus (1 - 1/{n})^4",
                keep[i]
            ),
            &d,
        );
    }
    // Printed, not asserted: whether MSE minimisation's paths lengthen after the flash (the
    // flash raises the records' squared-bias estimate) is a mechanism the lab measured, not a
    // relation of the paper, and it did not survive the BSDF's coupled diffuse (per seed +0.22,
    // −0.20, +0.05 vertices over seeds 3-5): docs/lab/termination-dynamics.md.
    let n = mse_length_change.len() as f64;
    eprintln!(
        "MSE minimisation: path length after the flash minus the control's: per seed {mse_length_change:.4?}, mean {:.4}",
        mse_length_change.iter().sum::<f64>() / n
    );
}

fn flip(records: &[FrameRecord], method: &str) -> f64 {
    records
        .iter()
        .find(|r| r.method == method)
        .and_then(|r| r.flip)
        .unwrap_or_else(|| panic!("{method}: no FLIP"))
}

#[test]
fn glossy_surfaces_bias_termination_into_direction_independent_records() {
    // The paper's Fig. 12 (glossy bias): the same Cornell box with diffuse walls (the event
    // removed) and with its white walls turned into rough metal. What terminating into the
    // cache costs is the FLIP of the first-vertex rule (every path ends in the record at its
    // primary hit) against the reference minus the path tracer's (same cache, same samples).
    // Variance bounding at relative t = 1 moved the same way in every seed but within the
    // seeds' spread (docs/lab/termination-dynamics.md, "Where a rule fails"); it is left out to keep the test short.
    let keep = ["first_vertex", "pt"];
    let mut excess = vec![];
    for &seed in &SEEDS {
        let glossy = play("termination_failure_glossy.ron", &keep, seed, 1, "glossy", |_| {});
        let diffuse = play("termination_failure_glossy.ron", &keep, seed, 1, "diffuse", |s| {
            s.scenario.events.clear()
        });
        let (g, d) = (
            flip(&glossy, "first_vertex") - flip(&glossy, "pt"),
            flip(&diffuse, "first_vertex") - flip(&diffuse, "pt"),
        );
        eprintln!(
            "seed {seed}: first-vertex FLIP minus path tracing's: glossy {g:.4}, diffuse {d:.4}"
        );
        excess.push(g - d);
    }
    assert_positive("first vertex: (FLIP - path tracing's FLIP), glossy minus diffuse", &excess);
}
