//! Suites over frames on disk (another renderer's): the example suite on the committed ColorVideoVDP
//! fixtures passes its gates; a renderer blessed on its frames passes against its baseline and
//! fails it once its frames get noisier; bad frames are errors at the case's line naming the
//! file and frame, with nothing written. No GPU is needed.

use std::path::{Path, PathBuf};

use tools::suite::gate::Verdict;
use tools::suite::{Suite, SuiteOptions, bless, run};

fn root() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).parent().unwrap().to_path_buf()
}

fn temp(name: &str) -> tempfile::TempDir {
    tempfile::Builder::new().prefix(&format!("flicker-suite-measured-{name}-")).tempdir().unwrap()
}

fn options(suite: PathBuf, dir: &Path) -> SuiteOptions {
    SuiteOptions {
        suite,
        out: Some(dir.join("out")),
        cache_dir: Some(dir.join("references")),
        baselines: None,
        progress: false,
    }
}

const SIZE: (u32, u32) = (24, 16);
const FRAMES: u32 = 6;

/// A pixel's noise in [-1, 1], fixed by (seed, frame, pixel): SplitMix64's finalizer.
fn noise(seed: u64, frame: u32, i: usize) -> f32 {
    let mut z = seed
        .wrapping_mul(0x9E37_79B9_7F4A_7C15)
        .wrapping_add(u64::from(frame) << 32)
        .wrapping_add(i as u64);
    z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
    z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
    z ^= z >> 31;
    (z >> 40) as f32 / (1u64 << 23) as f32 - 1.0
}

/// `FRAMES` EXRs of a horizontal ramp in `dir`, each pixel off by `amplitude` x its noise.
fn frames(dir: &Path, seed: u64, amplitude: f32) {
    std::fs::create_dir_all(dir).unwrap();
    let (w, h) = SIZE;
    for f in 0..FRAMES {
        let mut img = metrics::Image::filled(w, h, [0.0; 3]);
        for (i, p) in img.rgb.iter_mut().enumerate() {
            let ramp = 0.1 + 0.6 * (i as u32 % w) as f32 / w as f32;
            *p = [ramp * (1.0 + amplitude * noise(seed, f, i)); 3];
        }
        metrics::write_exr(&img, dir.join(format!("{f:04}.exr"))).unwrap();
    }
}

/// A renderer's output for seeds 1-3 under `dir`: `reference/`, `mine_SEED/`.
fn renderer(dir: &Path, amplitude: f32) {
    frames(&dir.join("reference"), 0, 0.0);
    for seed in 1..=3 {
        frames(&dir.join(format!("mine_{seed}")), seed, amplitude);
    }
}

/// Relative gates on the per-frame metrics and JOD, and an absolute one.
const SUITE: &str = r#"Suite(
    cases: [
        (name: "ramp", measure: (reference: "reference", tests: {"mine": "mine_{seed}"}, events: [3]), seeds: [1, 2, 3]),
    ],
    gates: [
        (metric: Smape, window: Steady(skip: 1), bound: Relative(tolerance: 0.1)),
        (metric: Flip, window: Before(event: 0), bound: Relative(tolerance: 0.1)),
        (metric: Cvvdp, window: Overall, bound: Relative(tolerance: 0.02)),
        (metric: Psnr, window: Overall, bound: Absolute(limit: 10.0)),
    ],
)"#;

#[test]
fn the_example_suite_passes_on_the_committed_frames() {
    let tmp = temp("example");
    let dir = tmp.path().to_path_buf();
    let path = root().join("suites/measured.ron");
    let outcome = run(&options(path.clone(), &dir)).expect("the example suite runs");
    eprintln!("{}", outcome.markdown);
    let suite = Suite::load(&path).unwrap();
    // Every gate judged each case's one test.
    assert_eq!(outcome.results.len(), suite.gates.len() * suite.cases.len());
    assert!(outcome.passed(), "{}", outcome.markdown);
    assert!(outcome.results.iter().any(|r| r.gate.starts_with("jod")));
    assert!(outcome.folder.join("flicker/seed_0/report.html").exists());
}

#[test]
fn a_blessed_renderer_passes_and_fails_once_its_frames_get_noisier() {
    let tmp = temp("bless");
    let dir = tmp.path().to_path_buf();
    renderer(&dir, 0.05);
    std::fs::write(dir.join("suite.ron"), SUITE).unwrap();
    let opts = options(dir.join("suite.ron"), &dir);
    let baseline = bless(&opts).expect("bless");
    assert_eq!(baseline, dir.join("baselines/suite.json"));
    let file: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(&baseline).unwrap()).unwrap();
    let seeds = &file["adapters"]["frames from disk / cpu"]["cases"]["ramp"]["seeds"];
    assert_eq!(seeds.as_array().map(Vec::len), Some(3), "{file}");
    assert!(seeds[0]["jod"]["mine"]["0..6"].is_f64(), "JOD kept for its gate: {file}");
    // The same frames again: every gate passes.
    let outcome = run(&opts).expect("suite runs");
    eprintln!("{}", outcome.markdown);
    assert_eq!(outcome.results.len(), 4);
    assert!(outcome.passed(), "{}", outcome.markdown);
    // Four times the noise: worse flicker, accuracy and JOD; the gates fail (not error).
    renderer(&dir, 0.2);
    let outcome = run(&opts).expect("suite runs");
    eprintln!("{}", outcome.markdown);
    for r in &outcome.results {
        let relative = !r.gate.starts_with("psnr");
        let expected = if relative { Verdict::Fail } else { Verdict::Pass };
        assert_eq!(r.verdict, expected, "{}: {}", r.gate, r.detail);
    }
}

#[test]
fn bad_frames_are_errors_at_the_case_line_and_nothing_is_written() {
    let tmp = temp("bad");
    let dir = tmp.path().to_path_buf();
    renderer(&dir, 0.05);
    let small = dir.join("small_1");
    std::fs::create_dir_all(&small).unwrap();
    for f in 0..FRAMES {
        let img = metrics::Image::filled(8, 8, [0.5; 3]);
        metrics::write_exr(&img, small.join(format!("{f:04}.exr"))).unwrap();
    }
    for seed in 1..=3 {
        let from = dir.join(format!("mine_{seed}"));
        let gap = dir.join(format!("gap_{seed}"));
        std::fs::create_dir_all(&gap).unwrap();
        for f in (0..FRAMES).filter(|&f| f != 2) {
            let name = format!("{f:04}.exr");
            std::fs::copy(from.join(&name), gap.join(&name)).unwrap();
        }
    }
    // The bad case is the second: the good one must not have been written either.
    let cases: [(&str, &[&str]); 3] = [
        ("missing_{seed}", &["missing_1", "cannot read the folder"]),
        ("small_{seed}", &["small_1/0000.exr", "frame 0", "8x8", "24x16"]),
        ("gap_{seed}", &["gap_1", "frame 2 is missing"]),
    ];
    for (folder, expected) in cases {
        let suite = format!(
            "Suite(\n  cases: [\n    (name: \"good\", measure: (reference: \"reference\", tests: {{\"mine\": \"mine_{{seed}}\"}}), seeds: [1, 2]),\n    (name: \"bad\", measure: (reference: \"reference\", tests: {{\"mine\": \"{folder}\"}}), seeds: [1, 2]),\n  ],\n  gates: [(metric: Smape, window: Overall, bound: Absolute(limit: 1.0))],\n)"
        );
        let path = dir.join("suite.ron");
        std::fs::write(&path, suite).unwrap();
        let e = format!("{:#}", run(&options(path.clone(), &dir)).err().expect("refused"));
        let at = format!("{}:4:5: case 'bad' seed 1: ", path.display());
        assert!(e.starts_with(&at), "{folder}: `{at}` does not start: {e}");
        for x in expected {
            assert!(e.contains(x), "{folder}: `{x}` not in: {e}");
        }
        assert!(!dir.join("out").exists(), "{folder}: something was written");
    }
    // Errors found when the file is read: the case's line.
    let load = |case: &str| {
        let text = format!(
            "Suite(\n  cases: [\n    {case},\n  ],\n  gates: [(metric: Flip, window: Overall, bound: Absolute(limit: 1.0))],\n)"
        );
        Suite::from_ron(&text, Path::new("s.ron")).expect_err("refused").to_string()
    };
    let cases: [(&str, &str); 5] = [
        (
            "(name: \"c\", measure: (reference: \"r\", tests: {\"m\": \"m\"}), seeds: [1, 2])",
            "no {seed} in its folder",
        ),
        ("(name: \"c\", measure: (reference: \"r_{seed}\", tests: {\"m\": \"m\"}))", "no seeds"),
        (
            "(name: \"c\", scenario: \"s.ron\", measure: (reference: \"r\", tests: {\"m\": \"m\"}))",
            "names a scenario and measure",
        ),
        (
            "(name: \"c\", measure: (reference: \"r\", tests: {\"m\": \"m\"}), frames: 8)",
            "frames sets how a scenario is played",
        ),
        ("(name: \"c\", seeds: [1])", "no scenario; expected scenario:"),
    ];
    for (case, expected) in cases {
        let e = load(case);
        assert!(e.starts_with("s.ron:3:5: case 'c': ") && e.contains(expected), "{case}: {e}");
    }
    // Relative folders resolve against the suite file's; no seeds is one run, seed 0.
    let ok = Suite::from_ron(
        "Suite(cases: [(name: \"c\", measure: (reference: \"r\", tests: {\"m\": \"/abs/m\"}))], gates: [(metric: Flip, window: Overall, bound: Absolute(limit: 1.0))])",
        Path::new("dir/s.ron"),
    )
    .unwrap();
    let m = ok.cases[0].measure.as_ref().unwrap();
    assert_eq!(
        (m.reference.as_path(), m.tests["m"].as_path()),
        (Path::new("dir/r"), Path::new("/abs/m"))
    );
    assert_eq!(ok.cases[0].seeds, [0]);
}
