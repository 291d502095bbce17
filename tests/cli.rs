//! End-to-end tests of the `flicker` program: runs, determinism, the run folder, bad input.

use std::path::{Path, PathBuf};
use std::process::{Command, Output};

fn flicker(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_flicker")).args(args).output().expect("flicker runs")
}

fn scratch(name: &str) -> tempfile::TempDir {
    tempfile::Builder::new().prefix(&format!("flicker-cli-{name}-")).tempdir().unwrap()
}

fn text(bytes: &[u8]) -> String {
    String::from_utf8_lossy(bytes).into_owned()
}

/// Runs `flicker run` expecting failure; returns stderr and checks nothing was written.
fn run_fails(scenario: &Path, extra: &[&str], out: &Path) -> String {
    let mut args =
        vec!["run", scenario.to_str().unwrap(), "--quiet", "--out", out.to_str().unwrap()];
    args.extend_from_slice(extra);
    let o = flicker(&args);
    let stderr = text(&o.stderr);
    assert!(!o.status.success(), "expected failure, got success; stderr: {stderr}");
    assert!(!out.exists(), "a failed run must not create its output folder {}", out.display());
    stderr
}

fn tiny_scenario(dir: &Path, body: &str) -> PathBuf {
    let path = dir.join("scenario.ron");
    std::fs::write(&path, body).unwrap();
    path
}

#[test]
fn malformed_ron_names_file_line_and_column() {
    let tmp = scratch("malformed");
    let dir = tmp.path().to_path_buf();
    let path = tiny_scenario(
        &dir,
        "Scenario(\n    scene: Builtin(\"cornell_box\"),\n    resolution: (16, 9)\n    frames: 2,\n)\n",
    );
    let err = run_fails(&path, &[], &dir.join("out"));
    assert!(err.contains("scenario.ron:4:"), "error should point at line 4: {err}");
}

#[test]
fn unknown_entity_is_an_error_before_frame_zero() {
    let tmp = scratch("entity");
    let dir = tmp.path().to_path_buf();
    let path = tiny_scenario(
        &dir,
        r#"Scenario(scene: Builtin("cornell_box"), resolution: (16, 9), frames: 2,
            methods: [PathTracing(spp: 1)],
            animations: [Rotate(entity: "no_such_box", axis: (0, 1, 0), degrees_per_second: 10)])"#,
    );
    let err = run_fails(&path, &[], &dir.join("out"));
    assert!(err.contains("no_such_box") && err.contains("scenario.ron"), "{err}");
}

#[test]
fn unknown_scene_and_missing_gltf_are_errors() {
    let tmp = scratch("scene");
    let dir = tmp.path().to_path_buf();
    let path = tiny_scenario(
        &dir,
        r#"Scenario(scene: Builtin("cornel_box"), resolution: (16, 9), frames: 2, methods: [PathTracing(spp: 1)])"#,
    );
    let err = run_fails(&path, &[], &dir.join("out"));
    assert!(
        err.contains("cornel_box") && err.contains("cornell_box"),
        "should list the known scenes: {err}"
    );

    let path = tiny_scenario(
        &dir,
        r#"Scenario(scene: Gltf("assets/missing.gltf"), resolution: (16, 9), frames: 2, methods: [PathTracing(spp: 1)])"#,
    );
    let err = run_fails(&path, &[], &dir.join("out"));
    assert!(err.contains("missing.gltf"), "{err}");
}

#[test]
fn oversize_resolution_is_refused_with_the_limit() {
    let tmp = scratch("oversize");
    let dir = tmp.path().to_path_buf();
    let err = run_fails(
        Path::new("scenarios/cornell_box.ron"),
        &["--resolution", "100000x8"],
        &dir.join("out"),
    );
    assert!(err.contains("100000") && err.contains("limit"), "{err}");
    let err = run_fails(
        Path::new("scenarios/cornell_box.ron"),
        &["--resolution", "160by90"],
        &dir.join("out"),
    );
    assert!(err.contains("WIDTHxHEIGHT"), "{err}");
}

#[test]
fn two_runs_give_byte_identical_frames_and_a_complete_run_folder() {
    let tmp = scratch("determinism");
    let dir = tmp.path().to_path_buf();
    let cache = dir.join("cache");
    let scenario = tiny_scenario(
        &dir,
        r#"Scenario(
            scene: Builtin("cornell_box"), resolution: (32, 18), frames: 3, seed: 7, max_depth: 4,
            methods: [PathTracing(spp: 1), PathTracing(spp: 2)],
            reference: (spp: 8, frames: List([1])),
            regions: [(name: "centre", x: 8, y: 4, w: 16, h: 10)],
        )"#,
    );
    let mut outs = Vec::new();
    for (i, expect_cached) in [(0, 0), (1, 1)] {
        let out = dir.join(format!("run{i}"));
        let o = flicker(&[
            "run",
            scenario.to_str().unwrap(),
            "--quiet",
            "--out",
            out.to_str().unwrap(),
            "--cache-dir",
            cache.to_str().unwrap(),
        ]);
        assert!(o.status.success(), "run failed: {}", text(&o.stderr));
        let stdout = text(&o.stdout);
        // The summary line, then the report's path, last.
        let lines: Vec<&str> = stdout.lines().collect();
        let [.., summary, report] = lines.as_slice() else {
            panic!("two lines expected: {stdout}")
        };
        assert!(
            summary.starts_with(&format!("wrote {} (", out.display()))
                && summary.ends_with(&format!("{expect_cached} from cache)")),
            "{stdout}"
        );
        assert_eq!(*report, format!("report: {}", out.join("report.html").display()), "{stdout}");
        outs.push(out);
    }
    for method in ["pt_1spp", "pt_2spp"] {
        for frame in 0..3 {
            let name = format!("frames/{method}/{frame:04}.exr");
            let a = std::fs::read(outs[0].join(&name)).unwrap();
            let b = std::fs::read(outs[1].join(&name)).unwrap();
            assert!(a == b, "{name} differs between two runs of the same scenario");
            assert!(outs[0].join(format!("frames/{method}/{frame:04}.png")).exists());
            // A still camera: its motion vectors, recorded for the report's viewer, are zero.
            let motion =
                metrics::load_image(outs[0].join(format!("frames/{method}/motion/{frame:04}.exr")))
                    .unwrap();
            assert!(
                motion.rgb.iter().all(|p| p[0] == 0.0 && p[1] == 0.0),
                "{method} frame {frame}: non-zero motion"
            );
        }
    }
    let run = &outs[0];
    assert!(run.join("reference/0001.exr").exists() && run.join("reference/0001.png").exists());
    assert!(!run.join("reference/0000.exr").exists());
    let manifest: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(run.join("manifest.json")).unwrap()).unwrap();
    assert_eq!(manifest["seed"], 7);
    assert_eq!(manifest["resolution"], serde_json::json!([32, 18]));
    assert!(manifest["adapter"]["name"].as_str().is_some_and(|n| !n.is_empty()));
    let csv = std::fs::read_to_string(run.join("frames.csv")).unwrap();
    let header: Vec<&str> = csv.lines().next().unwrap().split(',').collect();
    let rows: Vec<Vec<&str>> = csv.lines().skip(1).map(|l| l.split(',').collect()).collect();
    assert_eq!(rows.len(), 6, "one row per (method, frame)");
    let col = |name: &str| {
        header
            .iter()
            .position(|h| *h == name)
            .unwrap_or_else(|| panic!("no column {name} in {header:?}"))
    };
    for row in &rows {
        let frame: u32 = row[col("frame")].parse().unwrap();
        let flip = row[col("flip")];
        assert_eq!(flip.is_empty(), frame != 1, "FLIP exactly on the reference frame: {row:?}");
        assert_eq!(
            row[col("smape")].is_empty(),
            frame == 0,
            "SMAPE from the second frame on: {row:?}"
        );
        if frame == 1 {
            let f: f64 = flip.parse().unwrap();
            assert!(f > 0.0 && f < 1.0, "{f}");
            assert!(!row[col("centre_flip")].is_empty());
        }
    }
    assert!(run.join("summary.json").exists() && run.join("report.html").exists());
    let leftovers: Vec<_> =
        walk(run).into_iter().filter(|p| p.extension().is_some_and(|e| e == "tmp")).collect();
    assert!(leftovers.is_empty(), "temporary files left: {leftovers:?}");
}

/// A warm-started neural cache is the same bits when played again from fresh caches: each run
/// starts from an empty cache folder, so it renders its own reference and pre-trains its own
/// warm start (nothing loaded from the other run), and the two write byte-identical warm starts,
/// frames and per-frame numbers (measured times excepted). The independent repeat the
/// reproduce smoke test makes for its replayed papers, for the NIRC warm start at a tiny size.
#[test]
fn a_warm_started_neural_cache_gives_the_same_bits_from_fresh_caches() {
    let tmp = scratch("nirc-warm-start");
    let dir = tmp.path().to_path_buf();
    let scenario = tiny_scenario(
        &dir,
        r#"Scenario(
            scene: Builtin("cornell_box"), resolution: (16, 9), frames: 3, seed: 7, max_depth: 3,
            methods: [Nirc(spp: 1, pretrain_frames: 4,
                cache: (
                    encoding: (levels: 8, features_per_level: 2, log2_table_size: 12, base_resolution: 4, growth_factor: 1.5),
                    network: (width: 32, hidden_layers: 1),
                    reliability: (resolution: 16, log2_cells: 12, warmup: 16),
                    max_batch: 512,
                ),
                paths: (termination_vertex: 1, train_records: 512))],
            reference: (spp: 8, frames: List([2])),
        )"#,
    );
    let mut runs = Vec::new();
    for i in 0..2 {
        let (out, cache) = (dir.join(format!("run{i}")), dir.join(format!("cache{i}")));
        let o = flicker(&[
            "run",
            scenario.to_str().unwrap(),
            "--quiet",
            "--out",
            out.to_str().unwrap(),
            "--cache-dir",
            cache.to_str().unwrap(),
        ]);
        assert!(o.status.success(), "run failed: {}", text(&o.stderr));
        let stdout = text(&o.stdout);
        assert!(stdout.contains("references: 1 rendered, 0 from cache"), "{stdout}");
        let warm: Vec<PathBuf> = walk(&cache.join("nirc"))
            .into_iter()
            .filter(|p| p.extension().is_some_and(|e| e == "nirc"))
            .collect();
        assert_eq!(warm.len(), 1, "the run pre-trained and saved its warm start: {warm:?}");
        runs.push((out, warm[0].clone()));
    }
    let ((a, warm_a), (b, warm_b)) = (&runs[0], &runs[1]);
    assert_eq!(warm_a.file_name(), warm_b.file_name(), "the same warm-start key");
    assert!(
        std::fs::read(warm_a).unwrap() == std::fs::read(warm_b).unwrap(),
        "the warm starts pre-trained from fresh caches differ"
    );
    for frame in 0..3 {
        let name = format!("frames/nirc_blend_1spp/{frame:04}.exr");
        let (fa, fb) =
            (std::fs::read(a.join(&name)).unwrap(), std::fs::read(b.join(&name)).unwrap());
        assert!(fa == fb, "{name} differs between two runs from fresh caches");
    }
    // Every per-frame number but the measured times (FLIP, training loss, reliabilities, σ, ...).
    let numbers = |run: &Path| -> Vec<Vec<String>> {
        let csv = std::fs::read_to_string(run.join("frames.csv")).unwrap();
        let header: Vec<&str> = csv.lines().next().unwrap().split(',').collect();
        let keep: Vec<usize> = (0..header.len()).filter(|&i| !header[i].contains("ms")).collect();
        assert!(
            keep.iter().any(|&i| header[i] == "flip")
                && keep.iter().any(|&i| header[i] == "train_loss")
        );
        csv.lines()
            .map(|l| {
                let cells: Vec<&str> = l.split(',').collect();
                keep.iter().map(|&i| cells[i].to_string()).collect()
            })
            .collect()
    };
    let (na, nb) = (numbers(a), numbers(b));
    assert_eq!(na.len(), 4, "a header and three frames");
    assert_eq!(na, nb, "frames.csv's numbers differ between two runs from fresh caches");
}

#[test]
fn scenes_lists_every_builtin() {
    let o = flicker(&["scenes"]);
    assert!(o.status.success());
    let out = text(&o.stdout);
    for name in [
        "cornell_box",
        "corridor",
        "door_gap",
        "courtyard",
        "hairball",
        "rotating_cone",
        "sss_sphere",
    ] {
        assert!(out.contains(name), "{out}");
    }
}

fn walk(dir: &Path) -> Vec<PathBuf> {
    let mut out = Vec::new();
    for entry in std::fs::read_dir(dir).unwrap() {
        let p = entry.unwrap().path();
        if p.is_dir() {
            out.extend(walk(&p));
        } else {
            out.push(p);
        }
    }
    out
}

#[test]
fn schedule_lists_each_stage_and_the_methods_systems() {
    let o = flicker(&["schedule", "scenarios/light_rotation_cornell_box.ron"]);
    let out = text(&o.stdout);
    assert!(o.status.success(), "{}", text(&o.stderr));
    let at = |s: &str| out.find(s).unwrap_or_else(|| panic!("'{s}' missing from:\n{out}"));
    let stages: Vec<usize> =
        ["\nSimulate\n", "\nExtract\n", "\nRender\n", "\nLearn\n", "\nMeasure\n", "\nRecord\n"]
            .iter()
            .map(|s| at(s))
            .collect();
    assert!(stages.windows(2).all(|w| w[0] < w[1]), "stages out of order:\n{out}");
    assert!(at("nirc_blend_1spp (Nirc)") < stages[0]);
    assert!((stages[2]..stages[3]).contains(&at("nirc::infer")), "{out}");
    assert!((stages[3]..stages[4]).contains(&at("nirc::train")), "{out}");
    assert!((stages[2]..stages[3]).contains(&at("path_tracing::render")), "{out}");
    assert!(!out.contains("taa::"), "no TAA in this scenario:\n{out}");
}

#[test]
fn duplicate_method_labels_are_refused_before_anything_is_written() {
    let tmp = scratch("duplicate");
    let dir = tmp.path().to_path_buf();
    let path = tiny_scenario(
        &dir,
        "Scenario(scene: Builtin(\"cornell_box\"), resolution: (16, 9), frames: 2,\n  methods: [PathTracing(spp: 1),\n    PathTracing(spp: 1)])",
    );
    let err = run_fails(&path, &[], &dir.join("out"));
    assert!(
        err.contains("scenario.ron:3:5")
            && err.contains("scenario.ron:2:13")
            && err.contains("pt_1spp"),
        "{err}"
    );
}

#[test]
fn termination_survival_outside_0_1_is_refused_at_its_line() {
    for (setting, expected) in [
        ("survival: 1.5", "survival must be in (0, 1], got 1.5"),
        ("survival: 0.0", "survival must be in (0, 1], got 0"),
        ("radiance_unit: 0.0", "radiance_unit must be positive"),
    ] {
        let tmp = scratch("survival");
        let dir = tmp.path().to_path_buf();
        let path = tiny_scenario(
            &dir,
            &format!(
                "Scenario(scene: Builtin(\"cornell_box\"), resolution: (16, 9), frames: 1,\n  methods: [PathTracing(spp: 1),\n    Termination(rule: FirstVertex, {setting})],\n  reference: (spp: 4, frames: List([])))"
            ),
        );
        let err = run_fails(&path, &[], &dir.join("out"));
        assert!(err.contains("scenario.ron:3:5") && err.contains(expected), "{setting}: {err}");
    }
}

#[test]
fn no_xdg_runtime_dir_message_when_it_is_unset_or_invalid() {
    let tmp = scratch("xdg");
    let dir = tmp.path().to_path_buf();
    let scenario = tiny_scenario(
        &dir,
        r#"Scenario(scene: Builtin("cornell_box"), resolution: (16, 9), frames: 1, seed: 1, max_depth: 2,
            methods: [PathTracing(spp: 1)], reference: (spp: 4, frames: List([])))"#,
    );
    let run = |value: Option<&str>, name: &str| {
        let mut cmd = Command::new(env!("CARGO_BIN_EXE_flicker"));
        let out = dir.join(name);
        cmd.args([
            "run",
            scenario.to_str().unwrap(),
            "--quiet",
            "--out",
            out.to_str().unwrap(),
            "--cache-dir",
            dir.join("cache").to_str().unwrap(),
        ]);
        match value {
            Some(v) => cmd.env("XDG_RUNTIME_DIR", v),
            None => cmd.env_remove("XDG_RUNTIME_DIR"),
        };
        let o = cmd.output().expect("flicker runs");
        assert!(o.status.success(), "run failed: {}", text(&o.stderr));
        text(&o.stderr)
    };
    for (value, name) in [(None, "unset"), (Some("relative/dir"), "relative"), (Some(""), "empty")]
    {
        let stderr = run(value, name);
        assert!(!stderr.contains("XDG_RUNTIME_DIR"), "XDG_RUNTIME_DIR {value:?}: {stderr}");
    }
}

#[test]
fn suite_exit_codes_summary_and_junit() {
    let tmp = scratch("suite");
    let dir = tmp.path().to_path_buf();
    tiny_scenario(
        &dir,
        "Scenario(scene: Builtin(\"cornell_box\"), resolution: (16, 9), frames: 3, max_depth: 2, methods: [PathTracing(spp: 1)], reference: (spp: 8, frames: Every(1)))",
    );
    // One gate every image passes, one none can (FLIP is never below 0): exit code 1.
    let suite = dir.join("tiny.ron");
    std::fs::write(
        &suite,
        "Suite(\n  cases: [(name: \"box\", scenario: \"scenario.ron\", seeds: [1, 2])],\n  gates: [\n    (metric: Flip, window: Overall, bound: Absolute(limit: 1.0)),\n    (metric: Flip, window: Overall, bound: Absolute(limit: -0.1)),\n  ],\n)\n",
    )
    .unwrap();
    let out = dir.join("out");
    let o = flicker(&[
        "suite",
        "run",
        suite.to_str().unwrap(),
        "--quiet",
        "--out",
        out.to_str().unwrap(),
        "--cache-dir",
        dir.join("cache").to_str().unwrap(),
        "--history",
        dir.join("history").to_str().unwrap(),
    ]);
    assert_eq!(
        o.status.code(),
        Some(1),
        "stdout: {}\nstderr: {}",
        text(&o.stdout),
        text(&o.stderr)
    );
    let summary = std::fs::read_to_string(out.join("summary.md")).unwrap();
    assert!(
        summary.contains("1 of 2 checks failed")
            && summary.contains("**FAIL** | box | pt_1spp | flip overall <= -0.1"),
        "{summary}"
    );
    let junit = std::fs::read_to_string(out.join("junit.xml")).unwrap();
    assert!(junit.contains("tests=\"2\" skipped=\"0\" failures=\"1\" errors=\"0\""), "{junit}");
    assert!(
        out.join("box/seed_1/frames.csv").exists() && out.join("box/seed_2/report.html").exists()
    );
    history_of_the_suite(&dir.join("history"), &dir.join("shown"));
    // A bad suite file: exit code 2, the error at file:line.
    std::fs::write(&suite, "Suite(\n  cases: [],\n  gates: [(metric: Flip, window: Overall, bound: Absolute(limit: 1.0))],\n  extra: 1,\n)\n").unwrap();
    let o = flicker(&["suite", "run", suite.to_str().unwrap(), "--quiet"]);
    let stderr = text(&o.stderr);
    assert_eq!(o.status.code(), Some(2), "{stderr}");
    assert!(stderr.contains("tiny.ron:4:"), "{stderr}");
}

/// The suite run's record in the history (one entry per gate), and `flicker history` over it
/// and a copy at a later commit whose first gate failed: a verdict change, exit code 1 with
/// `--fail-on-change`.
fn history_of_the_suite(history: &Path, shown: &Path) {
    let records = tools::history::read(history).unwrap();
    assert_eq!(records.len(), 1);
    let (_, mut r) = records.into_iter().next().unwrap();
    assert_eq!(r.kind, tools::history::Kind::Suite);
    let verdicts: Vec<_> = r.entries.iter().map(|e| e.verdict.clone().unwrap()).collect();
    assert_eq!(verdicts, ["pass", "fail"]);
    assert!(r.entries.iter().all(|e| e.value.is_some() && e.lo.is_some()), "{:?}", r.entries);
    let o = flicker(&[
        "history",
        "--history",
        history.to_str().unwrap(),
        "--out",
        shown.to_str().unwrap(),
        "--fail-on-change",
    ]);
    assert_eq!(o.status.code(), Some(0), "one commit changes nothing: {}", text(&o.stderr));
    (r.commit, r.date) = ("f".repeat(40), "2999-01-01T00:00:00Z".into());
    r.entries[0].verdict = Some("fail".into());
    tools::history::append(history, &r).unwrap();
    let args =
        ["history", "--history", history.to_str().unwrap(), "--out", shown.to_str().unwrap()];
    let o = flicker(&args);
    assert_eq!(o.status.code(), Some(0), "{}", text(&o.stderr));
    let o = flicker(&[&args[..], &["--fail-on-change"]].concat());
    assert_eq!(o.status.code(), Some(1), "{}", text(&o.stderr));
    let stdout = text(&o.stdout);
    assert!(
        stdout.contains("| fffffff | 2999-01-01T00:00:00Z |")
            && stdout.contains("**verdict changed: pass -> fail**"),
        "{stdout}"
    );
    assert!(
        text(&o.stderr).contains("changed at the latest commit: box/pt_1spp/flip overall <= 1"),
        "{}",
        text(&o.stderr)
    );
    let charts = std::fs::read_dir(shown.join("charts")).unwrap().count();
    assert_eq!(charts, 2, "a chart per gate");
    assert!(std::fs::read_to_string(shown.join("history.md")).unwrap().contains("verdict changed"));
}
