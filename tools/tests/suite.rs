//! `flicker suite`: the smoke suite against its blessed lavapipe baseline (a stand-in on any
//! other adapter), the same suite with a deliberately broken method (NIRC's test-only
//! `test_skip_ema`), a missing baseline, and bad suite files reported at file:line.

use std::path::{Path, PathBuf};

use tools::suite::gate::Verdict;
use tools::suite::{Suite, SuiteOptions, run};

fn root() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).parent().unwrap().to_path_buf()
}

fn temp(name: &str) -> tempfile::TempDir {
    tempfile::Builder::new().prefix(&format!("flicker-suite-{name}-")).tempdir().unwrap()
}

fn options(suite: PathBuf, dir: &Path, baselines: Option<PathBuf>) -> SuiteOptions {
    SuiteOptions {
        suite,
        out: Some(dir.join("out")),
        cache_dir: Some(dir.join("references")),
        baselines,
        progress: false,
    }
}

/// Every method kind the scenario format has.
const METHODS: [&str; 6] =
    ["pt_1spp", "nirc_ema_1spp", "nirc_blend_1spp", "taa", "hash_cache", "ssc_adaptive"];

#[test]
fn smoke_suite_passes_against_its_baseline() {
    let tmp = temp("smoke");
    let dir = tmp.path().to_path_buf();
    let started = std::time::Instant::now();
    let outcome =
        run(&options(root().join("suites/smoke.ron"), &dir, None)).expect("smoke suite runs");
    eprintln!("smoke suite: {:.1} s\n{}", started.elapsed().as_secs_f64(), outcome.markdown);
    let suite = Suite::load(&root().join("suites/smoke.ron")).unwrap();
    // Every gate judged every method of the case.
    assert_eq!(outcome.results.len(), suite.gates.len() * METHODS.len());
    for m in METHODS {
        assert!(outcome.results.iter().any(|r| r.method == m), "{m} was not judged");
    }
    assert!(outcome.passed(), "smoke suite failed:\n{}", outcome.markdown);
    let junit = std::fs::read_to_string(&outcome.junit).unwrap();
    assert!(
        junit.contains(&format!(
            "tests=\"{}\" skipped=\"0\" failures=\"0\" errors=\"0\"",
            outcome.results.len()
        )),
        "{junit}"
    );
    // Each case's run folder has its report.
    assert!(outcome.folder.join("cornell/seed_2/report.html").exists());
}

#[test]
fn broken_nirc_fails_the_smoke_suite() {
    // The smoke suite, its scenario's NIRC methods with the EMA update switched off, judged
    // against the committed baseline.
    let tmp = temp("broken");
    let dir = tmp.path().to_path_buf();
    let scenario =
        std::fs::read_to_string(root().join("suites/scenarios/smoke_cornell.ron")).unwrap();
    let broken = scenario.replace("Nirc(spp: 1,", "Nirc(spp: 1, test_skip_ema: true,");
    assert_eq!(broken.matches("test_skip_ema").count(), 2);
    std::fs::write(dir.join("smoke_cornell.ron"), broken).unwrap();
    let suite = std::fs::read_to_string(root().join("suites/smoke.ron"))
        .unwrap()
        .replace("scenarios/smoke_cornell.ron", "smoke_cornell.ron");
    std::fs::write(dir.join("smoke.ron"), suite).unwrap();
    let outcome = run(&options(
        dir.join("smoke.ron"),
        &dir,
        Some(root().join("suites/baselines/smoke.json")),
    ))
    .expect("suite runs");
    eprintln!("{}", outcome.markdown);
    assert!(!outcome.passed());
    // Only the broken methods fail, and by failing a gate, not by an error.
    for r in &outcome.results {
        assert!(!matches!(r.verdict, Verdict::Error(_)), "{r:?}");
        if !r.method.starts_with("nirc_") {
            assert!(r.passed(), "{} should pass: {}", r.method, r.detail);
        }
    }
    assert!(
        outcome.results.iter().any(|r| r.method == "nirc_ema_1spp" && r.verdict == Verdict::Fail)
    );
    let junit = std::fs::read_to_string(&outcome.junit).unwrap();
    assert!(junit.contains("<failure message="), "{junit}");
}

#[test]
fn a_missing_baseline_says_how_to_bless_one() {
    let tmp = temp("missing");
    let dir = tmp.path().to_path_buf();
    let err = run(&options(root().join("suites/smoke.ron"), &dir, Some(dir.join("none.json"))))
        .err()
        .expect("no baseline is an error")
        .to_string();
    assert!(
        err.contains("no baseline for adapter")
            && err.contains("flicker suite bless")
            && err.contains("suites/smoke.ron"),
        "{err}"
    );
    // Nothing was played.
    assert!(!dir.join("out/cornell").exists());
}

fn load_error(text: &str) -> String {
    Suite::from_ron(text, Path::new("bad.ron")).expect_err("refused").to_string()
}

#[test]
fn bad_suite_files_are_reported_at_file_line() {
    let case = "(name: \"c\", scenario: \"s.ron\", seeds: [1, 2])";
    // A syntax error in a gate, on line 4.
    let e = load_error(&format!(
        "Suite(\n    cases: [{case}],\n    gates: [\n        (metric: Flip, window: Overall, bound: Relative(tolerance: 0.05),,\n    ],\n)"
    ));
    assert!(e.starts_with("bad.ron:4:"), "{e}");
    // An unknown metric on line 3, column of the value.
    let e = load_error(&format!(
        "Suite(\n    cases: [{case}],\n    gates: [(metric: Flipp, window: Overall, bound: Absolute(limit: 1.0))],\n)"
    ));
    assert!(e.starts_with("bad.ron:3:") && e.contains("Flipp"), "{e}");
    // A gate naming a case that does not exist: the gate's line.
    let e = load_error(&format!(
        "Suite(\n    cases: [{case}],\n    gates: [\n      (metric: Flip, window: Overall, bound: Absolute(limit: 1.0), cases: [\"x\"]),\n    ],\n)"
    ));
    assert_eq!(e, "bad.ron:4:7: gate names case 'x'; the suite's cases are: c");
    // A relative gate on a one-seed case.
    let e = load_error(
        "Suite(\n  cases: [\n    (name: \"c\", scenario: \"s.ron\", seeds: [1]),\n  ],\n  gates: [(metric: Smape, window: Overall, bound: Relative(tolerance: 0.1))],\n)",
    );
    assert!(e.starts_with("bad.ron:5:11: a relative gate needs the spread over seeds"), "{e}");
    // Unknown field in a case, line 2.
    let e = load_error(
        "Suite(\n  cases: [(name: \"c\", scenario: \"s.ron\", seeds: [1, 2], framez: 3)],\n  gates: [(metric: Smape, window: Overall, bound: Relative(tolerance: 0.1))],\n)",
    );
    assert!(e.starts_with("bad.ron:2:") && e.contains("framez"), "{e}");
    // A metric only `flicker reproduce` reads (PassMs needs a claim's passes): the gate's line.
    let e = load_error(&format!(
        "Suite(\n    cases: [{case}],\n    gates: [\n      (metric: PassMs, window: Overall, bound: Absolute(limit: 1.0)),\n    ],\n)"
    ));
    assert!(e.starts_with("bad.ron:4:7: metric pass_ms"), "{e}");
    // σ by region is computed from a run's preference maps: also the gate's line.
    let e = load_error(&format!(
        "Suite(\n    cases: [{case}],\n    gates: [\n      (metric: SigmaChanged, window: Overall, bound: Absolute(limit: 1.0)),\n    ],\n)"
    ));
    assert!(e.starts_with("bad.ron:4:7: metric sigma_changed"), "{e}");
    // Windows that can hold no frame: the gate's line.
    let e = load_error(&format!(
        "Suite(\n    cases: [{case}],\n    gates: [\n      (metric: Flip, window: After(event: 0, frames: 0), bound: Absolute(limit: 1.0)),\n    ],\n)"
    ));
    assert!(
        e.starts_with("bad.ron:4:7: window after_event_0(0): frames: 0 is an empty window"),
        "{e}"
    );
    let e = load_error(&format!(
        "Suite(\n    cases: [{case}],\n    gates: [\n      (metric: Flip, window: Around(event: 0, from: 2, to: 2), bound: Absolute(limit: 1.0)),\n    ],\n)"
    ));
    assert!(e.starts_with("bad.ron:4:7: window event_0+2..+2: from: 2 is not before to: 2"), "{e}");
    // A stand-in baseline's widening must be a fraction >= 0.
    let e = load_error(&format!(
        "Suite(\n    other_adapter_tolerance: -0.1,\n    cases: [{case}],\n    gates: [(metric: Flip, window: Overall, bound: Absolute(limit: 1.0))],\n)"
    ));
    assert!(
        e.starts_with("bad.ron:2:5: other_adapter_tolerance -0.1; expected a fraction >= 0"),
        "{e}"
    );
    // Relative scenario paths resolve against the suite's folder.
    let ok = Suite::from_ron(&format!("Suite(cases: [{case}], gates: [(metric: Flip, window: Overall, bound: Absolute(limit: 1.0))])"), Path::new("dir/bad.ron")).unwrap();
    assert_eq!(ok.cases[0].scenario, Path::new("dir/s.ron"));
    assert_eq!(ok.baseline_file(), Path::new("dir/baselines/bad.json"));
}
