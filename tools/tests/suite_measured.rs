//! Suites over frames on disk (another renderer's): the example suite on the committed ColorVideoVDP
//! fixtures passes its gates; a renderer blessed on its frames passes against its baseline and
//! fails it once its frames get noisier; bad frames are errors at the case's line naming the
//! file and frame, with nothing written; a baseline blessed on another adapter stands in with a
//! wider tolerance. A case over a `flicker export` package takes the package's references, frame
//! rate and events, and an outside method's timings gate on its FrameMs. No GPU is needed.

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
fn another_adapters_baseline_stands_in_with_a_wider_tolerance() {
    let tmp = temp("stand_in");
    let dir = tmp.path().to_path_buf();
    renderer(&dir, 0.05);
    std::fs::write(dir.join("suite.ron"), SUITE).unwrap();
    let opts = options(dir.join("suite.ron"), &dir);
    let path = bless(&opts).expect("bless");
    // The baseline as if blessed on a GPU only: this adapter has none of its own.
    let text = std::fs::read_to_string(&path)
        .unwrap()
        .replace("frames from disk / cpu", "Some GPU (driver 1.2) / Vulkan");
    std::fs::write(&path, text).unwrap();
    let outcome = run(&opts).expect("a stand-in baseline is used, not an error");
    eprintln!("{}", outcome.markdown);
    assert!(
        outcome.markdown.contains("no baseline blessed on adapter 'frames from disk / cpu'")
            && outcome.markdown.contains("'Some GPU (driver 1.2) / Vulkan'")
            && outcome.markdown.contains("flicker suite bless"),
        "{}",
        outcome.markdown
    );
    // Each relative gate's tolerance grew by the default other_adapter_tolerance, 0.05.
    let tolerances: Vec<&str> = outcome.results.iter().map(|r| r.gate.as_str()).collect();
    assert!(tolerances.iter().any(|g| g.ends_with("within 15.0% of baseline")), "{tolerances:?}");
    assert!(tolerances.iter().any(|g| g.ends_with("within 7.0% of baseline")), "{tolerances:?}");
    assert!(outcome.passed(), "{}", outcome.markdown);
    // Four times the noise still fails the widened relative gates.
    renderer(&dir, 0.2);
    let outcome = run(&opts).expect("suite runs");
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
    let cases: [(&str, &str); 8] = [
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
        ("(name: \"c\", measure: (tests: {\"m\": \"m\"}))", "no reference; expected reference:"),
        (
            "(name: \"c\", measure: (reference: \"r\", scenario: \"p\", tests: {\"m\": \"m\"}))",
            "names a reference and a scenario package",
        ),
        (
            "(name: \"c\", measure: (scenario: \"p\", tests: {\"m\": \"m\"}, timings: {\"n\": \"t.csv\"}))",
            "timings names 'n', which is not a test",
        ),
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
        (m.reference.as_deref(), m.tests["m"].as_path()),
        (Some(Path::new("dir/r")), Path::new("/abs/m"))
    );
    assert_eq!(ok.cases[0].seeds, [0]);
}

/// A `flicker export` package as `flicker measure --scenario` reads it, without a GPU: the
/// manifest (24 fps, one event at frame 3, a display) and the ramp as its references.
fn package(dir: &Path) {
    frames(&dir.join("reference"), 0, 0.0);
    let manifest = serde_json::json!({
        "format": "flicker-export",
        "frames": FRAMES,
        "fps": 24.0,
        "events": [{"frame": 3, "label": "toggle 'lamp'"}],
        "cvvdp": {"display": "standard_fhd", "exposure": 1.0},
        "smape_epsilon": 0.01,
        "reference": {"dir": "reference"},
    });
    std::fs::write(dir.join("manifest.json"), manifest.to_string()).unwrap();
}

/// Per-frame times of seed `seed`: `scale` x (4 ms + a little per seed and frame), split into
/// two passes.
fn times(dir: &Path, seed: u64, scale: f64) -> PathBuf {
    let mut text = String::from("frame,ms,trace,accumulate\n");
    for f in 0..FRAMES {
        let ms = scale * (4.0 + 0.1 * seed as f64 + 0.05 * f as f64);
        text.push_str(&format!("{f},{ms},{},{}\n", 0.75 * ms, 0.2 * ms));
    }
    let path = dir.join(format!("times_{seed}.csv"));
    std::fs::write(&path, text).unwrap();
    path
}

const PACKAGE_SUITE: &str = r#"Suite(
    cases: [
        (
            name: "outside",
            measure: (
                scenario: "package",
                tests: {"mine": "mine_{seed}"},
                timings: {"mine": "times_{seed}.csv"},
            ),
            seeds: [1, 2, 3],
        ),
    ],
    gates: [
        (metric: FrameMs, window: Overall, bound: Relative(tolerance: 0.1)),
        (metric: FrameMs, window: Overall, bound: Absolute(limit: 20.0)),
        (metric: Flip, window: After(event: 0, frames: 2), bound: Relative(tolerance: 0.1)),
    ],
)"#;

/// A case over a package: its frame rate and events reach the run folders (the `After(event: 0)`
/// gate is judged, not an error); the outside method's timings are blessed and gated: twice
/// slower fails the relative FrameMs gate only. A package missing a reference frame and timings
/// of the wrong length are errors at the case's line naming the file and frame, with nothing
/// written.
#[test]
fn a_package_case_gates_an_outside_methods_frames_and_times() {
    let tmp = temp("package");
    let dir = tmp.path().to_path_buf();
    package(&dir.join("package"));
    for seed in 1..=3 {
        frames(&dir.join(format!("mine_{seed}")), seed, 0.05);
        times(&dir, seed, 1.0);
    }
    std::fs::write(dir.join("suite.ron"), PACKAGE_SUITE).unwrap();
    let opts = options(dir.join("suite.ron"), &dir);
    bless(&opts).expect("bless");
    let outcome = run(&opts).expect("suite runs");
    eprintln!("{}", outcome.markdown);
    assert_eq!(outcome.results.len(), 3);
    assert!(outcome.passed(), "{}", outcome.markdown);
    let manifest: serde_json::Value = serde_json::from_str(
        &std::fs::read_to_string(outcome.folder.join("outside/seed_2/manifest.json")).unwrap(),
    )
    .unwrap();
    assert_eq!(manifest["events"][0]["label"], "toggle 'lamp'", "{manifest}");
    assert!((manifest["settings"]["time_step"].as_f64().unwrap() - 1.0 / 24.0).abs() < 1e-12);
    assert_eq!(manifest["settings"]["cvvdp"]["display"], "standard_fhd");
    let csv = std::fs::read_to_string(outcome.folder.join("outside/seed_2/frames.csv")).unwrap();
    assert!(csv.lines().next().unwrap().contains("wall_ms_trace"), "{csv}");
    // The same frames, twice as slow.
    for seed in 1..=3 {
        times(&dir, seed, 2.0);
    }
    let outcome = run(&opts).expect("suite runs");
    eprintln!("{}", outcome.markdown);
    let verdicts: Vec<(String, Verdict)> =
        outcome.results.iter().map(|r| (r.gate.clone(), r.verdict.clone())).collect();
    assert_eq!(
        verdicts.iter().map(|v| v.1.clone()).collect::<Vec<_>>(),
        [Verdict::Fail, Verdict::Pass, Verdict::Pass],
        "{verdicts:?}"
    );
    std::fs::remove_dir_all(dir.join("out")).unwrap();
    // Bad inputs: the first seed's timings one row short, then the package missing a frame.
    let short = times(&dir, 1, 1.0);
    let text = std::fs::read_to_string(&short).unwrap();
    std::fs::write(&short, text.lines().take(FRAMES as usize).collect::<Vec<_>>().join("\n"))
        .unwrap();
    let at = format!("{}:3:9: case 'outside' seed 1: ", dir.join("suite.ron").display());
    let e = format!("{:#}", run(&opts).err().expect("refused"));
    assert!(e.starts_with(&at), "{e}");
    assert!(e.contains("times_1.csv") && e.contains("frame 5 is missing"), "{e}");
    assert!(!dir.join("out").exists(), "something was written");
    times(&dir, 1, 1.0);
    std::fs::remove_file(dir.join("package/reference/0004.exr")).unwrap();
    let e = format!("{:#}", run(&opts).err().expect("refused"));
    assert!(e.starts_with(&at), "{e}");
    assert!(e.contains("reference/0004.exr") && e.contains("frame 4 is missing"), "{e}");
    assert!(!dir.join("out").exists(), "something was written");
}
