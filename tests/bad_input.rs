//! Every bad input a user can give `flicker run`, `flicker suite` or `flicker measure`: a clear error naming the
//! file (at line:column where there is one) and what was expected, nothing written, no panic.
//! All but the last three fail before the GPU is opened.

use std::path::{Path, PathBuf};
use std::process::{Command, Output};

fn flicker(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_flicker")).args(args).output().expect("flicker runs")
}

fn scratch(name: &str) -> tempfile::TempDir {
    tempfile::Builder::new().prefix(&format!("flicker-bad-{name}-")).tempdir().unwrap()
}

fn text(bytes: &[u8]) -> String {
    String::from_utf8_lossy(bytes).into_owned()
}

/// `flicker ARGS` must fail cleanly: exit code 1 or 2, no panic, `out` not created; its stderr.
fn fails(args: &[&str], out: &Path) -> String {
    let o = flicker(args);
    let stderr = text(&o.stderr);
    assert!(matches!(o.status.code(), Some(1 | 2)), "{args:?}: {:?}\n{stderr}", o.status);
    assert!(!stderr.contains("panicked"), "{args:?} panicked:\n{stderr}");
    assert!(!out.exists(), "{args:?}: a failed run must not create {}", out.display());
    stderr
}

fn run_fails(scenario: &Path, extra: &[&str]) -> String {
    let out = scenario.with_file_name("out");
    let mut args =
        vec!["run", scenario.to_str().unwrap(), "--quiet", "--out", out.to_str().unwrap()];
    args.extend_from_slice(extra);
    fails(&args, &out)
}

const BASE: &str = "scene: Builtin(\"cornell_box\"), resolution: (8, 8), frames: 1";

#[test]
fn non_finite_numbers_are_refused_at_their_line_and_column() {
    let tmp = scratch("finite");
    let dir = tmp.path().to_path_buf();
    let path = dir.join("scenario.ron");
    // Each case: a field written with a value that is not finite, on line 3 at the column of
    // the value, the key named.
    for (field, key) in [
        ("camera: (position: (0, 1, NaN), target: (0, 1, 0), vfov_degrees: 40)", "position"),
        ("camera: (position: (0, 1, 3), target: (0, 1, 0), vfov_degrees: inf)", "vfov_degrees"),
        ("environment: (0.5, -inf, 0)", "environment"),
        (
            "animations: [Rotate(entity: \"tall_box\", axis: (0, 1, 0), degrees_per_second: NaN)]",
            "degrees_per_second",
        ),
        (
            "animations: [Flash(entity: \"ceiling_light\", waveform: Sine(frequency: inf))]",
            "frequency",
        ),
        (
            "animations: [Keyframes(entity: \"tall_box\", keys: [(frame: 0, translation: (0, 1e39, 0))])]",
            "translation",
        ),
        (
            "events: [(frame: 0, action: SetMaterial(material: \"white\", roughness: NaN))]",
            "roughness",
        ),
        ("time_step: inf", "time_step"),
    ] {
        let body = format!("Scenario({BASE},\n  methods: [PathTracing(spp: 1)],\n  {field},\n)\n");
        std::fs::write(&path, &body).unwrap();
        let err = run_fails(&path, &[]);
        let line3 = body.lines().nth(2).unwrap();
        let literal = ["-inf", "NaN", "inf", "1e39"].iter().find_map(|l| line3.find(l)).unwrap();
        // time_step's own check points at its key.
        let column = if key == "time_step" { 3 } else { literal + 1 };
        let at = format!("scenario.ron:3:{column}:");
        assert!(err.contains(&at) && err.contains(key), "{field}: expected {at} and {key}: {err}");
        assert!(err.contains("finite") || err.contains("positive"), "{field}: {err}");
    }
    // A medium's extinction and a method's setting, the same way.
    for (field, expect) in [
        (
            "media: [(name: \"fog\", kind: Homogeneous, box_min: (-1, -1, -1), box_max: (1, 1, 1), sigma_t: NaN)]",
            "sigma_t",
        ),
        ("methods: [Taa(alpha: NaN)]", "alpha"),
    ] {
        let methods = if field.starts_with("methods") { "" } else { "methods: [VolumePath()]," };
        std::fs::write(&path, format!("Scenario({BASE}, {methods}\n  {field})\n")).unwrap();
        let err = run_fails(&path, &[]);
        assert!(err.contains("scenario.ron:2:") && err.contains(expect), "{field}: {err}");
    }
}

#[test]
fn zero_frames_and_no_methods_are_refused() {
    let tmp = scratch("counts");
    let dir = tmp.path().to_path_buf();
    let path = dir.join("scenario.ron");
    std::fs::write(
        &path,
        "Scenario(scene: Builtin(\"cornell_box\"), resolution: (8, 8),\n  frames: 0,\n  methods: [PathTracing(spp: 1)])",
    )
    .unwrap();
    let err = run_fails(&path, &[]);
    assert!(err.contains("scenario.ron:2:3:") && err.contains("at least 1"), "{err}");
    std::fs::write(&path, format!("Scenario({BASE},\n  methods: [])")).unwrap();
    let err = run_fails(&path, &[]);
    assert!(err.contains("scenario.ron:2:3:") && err.contains("PathTracing"), "{err}");
    // The command line's override, too.
    std::fs::write(&path, format!("Scenario({BASE}, methods: [PathTracing(spp: 1)])")).unwrap();
    let err = run_fails(&path, &["--frames", "0"]);
    assert!(err.contains("scenario.ron") && err.contains("at least 1"), "{err}");
}

#[test]
fn a_missing_scenario_file_is_named() {
    let tmp = scratch("missing");
    let dir = tmp.path().to_path_buf();
    let err = run_fails(&dir.join("no_such.ron"), &[]);
    assert!(err.contains("no_such.ron") && err.contains("cannot read"), "{err}");
}

/// `flicker measure --scenario` (the command line's path through a package): a package missing a
/// reference frame, and timings one row short, are errors naming the file and frame, with
/// nothing written; the good inputs are measured (so the errors come from the bad files).
#[test]
fn measure_names_a_packages_missing_frame_and_short_timings() {
    let tmp = scratch("measure");
    let dir = tmp.path().to_path_buf();
    let package = dir.join("package");
    let manifest = r#"{"format": "flicker-export", "frames": 4, "fps": 30.0,
        "events": [{"frame": 2, "label": "toggle 'lamp'"}],
        "cvvdp": {"display": "standard_fhd", "exposure": 1.0}, "smape_epsilon": 0.01,
        "reference": {"dir": "reference", "spp": 4}}"#;
    std::fs::create_dir_all(&package).unwrap();
    std::fs::write(package.join("manifest.json"), manifest).unwrap();
    for (folder, v) in [("reference", 0.5), ("mine", 0.45)] {
        std::fs::create_dir_all(dir.join(folder)).unwrap();
        for k in 0..4 {
            let img = metrics::Image::filled(8, 8, [v + 0.01 * k as f32; 3]);
            metrics::write_exr(&img, dir.join(folder).join(format!("{k:04}.exr"))).unwrap();
        }
    }
    std::fs::rename(dir.join("reference"), package.join("reference")).unwrap();
    std::fs::write(dir.join("short.csv"), "frame,ms\n0,1\n1,1\n2,1\n").unwrap();
    std::fs::write(dir.join("good.csv"), "frame,ms\n0,1\n1,1\n2,1\n3,1.5\n").unwrap();
    let out = dir.join("out");
    let measure = |timings: &str| {
        let (p, m, t, o) =
            (package.to_str().unwrap(), dir.join("mine"), dir.join(timings), out.to_str().unwrap());
        let (m, t) = (format!("mine={}", m.display()), format!("mine={}", t.display()));
        vec!["measure", "--scenario", p, "--test", &m, "--timings", &t, "--out", o]
            .into_iter()
            .map(String::from)
            .collect::<Vec<_>>()
    };
    let args = measure("short.csv");
    let err = fails(&args.iter().map(String::as_str).collect::<Vec<_>>(), &out);
    assert!(err.contains("short.csv") && err.contains("frame 3 is missing"), "{err}");
    let args = measure("good.csv");
    let args: Vec<&str> = args.iter().map(String::as_str).collect();
    let ok = flicker(&args);
    assert!(ok.status.success(), "{}", text(&ok.stderr));
    std::fs::remove_dir_all(&out).unwrap();
    std::fs::remove_file(package.join("reference/0002.exr")).unwrap();
    let err = fails(&args, &out);
    assert!(err.contains("reference/0002.exr") && err.contains("frame 2 is missing"), "{err}");
}

#[test]
fn an_unwritable_out_is_named_and_nothing_is_written() {
    let tmp = scratch("unwritable");
    let dir = tmp.path().to_path_buf();
    let path = dir.join("scenario.ron");
    std::fs::write(&path, format!("Scenario({BASE}, methods: [PathTracing(spp: 1)], reference: (spp: 1, frames: List([])))")).unwrap();
    // A path under a file can be created by no one (permissions would not stop root).
    std::fs::write(dir.join("file"), "keep").unwrap();
    let out = dir.join("file/run");
    let err = fails(
        &[
            "run",
            path.to_str().unwrap(),
            "--quiet",
            "--out",
            out.to_str().unwrap(),
            "--cache-dir",
            dir.join("cache").to_str().unwrap(),
        ],
        &out,
    );
    assert!(err.contains("file/run") && err.contains("Not a directory"), "{err}");
    assert_eq!(std::fs::read_to_string(dir.join("file")).unwrap(), "keep");
}

#[test]
fn a_resolution_over_the_buffer_limit_is_refused_with_the_limit() {
    // From the adapter's limits: the widest image its 2D textures hold, and just enough rows
    // that one RGBA f32 value a pixel (every method's image) is over its storage-buffer limit.
    let gpu = render::gpu::Gpu::new().expect("a wgpu adapter (lavapipe on CI)");
    let width = gpu.limits.max_texture_dimension_2d;
    let limit = gpu.limits.max_storage_buffer_binding_size.min(gpu.limits.max_buffer_size);
    let height = limit / (u64::from(width) * 16) + 1;
    assert!(height <= u64::from(width), "this adapter's buffers hold any image its textures do");
    drop(gpu);
    let tmp = scratch("buffer");
    let dir = tmp.path().to_path_buf();
    let path = dir.join("scenario.ron");
    std::fs::write(&path, format!("Scenario({BASE},\n  methods: [PathTracing(spp: 1)], reference: (spp: 1, frames: List([])))")).unwrap();
    let err = run_fails(&path, &["--resolution", &format!("{width}x{height}")]);
    assert!(
        err.contains("scenario.ron:2:13:")
            && err.contains("buffer")
            && err.contains(&format!("limit of {limit}")),
        "{width}x{height}: {err}"
    );
}

#[test]
fn a_malformed_baseline_is_named_at_its_line_before_anything_plays() {
    let tmp = scratch("baseline");
    let dir = tmp.path().to_path_buf();
    std::fs::write(
        dir.join("scenario.ron"),
        format!("Scenario({BASE}, methods: [PathTracing(spp: 1)])"),
    )
    .unwrap();
    let suite = dir.join("suite.ron");
    std::fs::write(&suite, "Suite(\n  cases: [(name: \"box\", scenario: \"scenario.ron\", seeds: [1, 2])],\n  gates: [(metric: Flip, window: Overall, bound: Absolute(limit: 1.0))],\n)\n").unwrap();
    let baselines = dir.join("baselines.json");
    std::fs::write(&baselines, "{\n  \"suite\": \"suite\",\n  \"adapters\": {,\n}\n").unwrap();
    let out = dir.join("out");
    for action in ["run", "bless"] {
        let err = fails(
            &[
                "suite",
                action,
                suite.to_str().unwrap(),
                "--quiet",
                "--out",
                out.to_str().unwrap(),
                "--baselines",
                baselines.to_str().unwrap(),
            ],
            &out,
        );
        assert!(err.contains("baselines.json:3:") && err.contains("baseline"), "{action}: {err}");
    }
}

#[test]
fn a_damaged_cached_reference_is_reported_and_rendered_again() {
    let tmp = scratch("cache");
    let dir = tmp.path().to_path_buf();
    let cache = dir.join("cache");
    let path = dir.join("scenario.ron");
    std::fs::write(&path, format!("Scenario({BASE}, seed: 2, max_depth: 2, methods: [PathTracing(spp: 1)], reference: (spp: 4, frames: Every(1)))")).unwrap();
    let run = |name: &str| {
        let out = dir.join(name);
        let o = flicker(&[
            "run",
            path.to_str().unwrap(),
            "--quiet",
            "--out",
            out.to_str().unwrap(),
            "--cache-dir",
            cache.to_str().unwrap(),
        ]);
        assert!(o.status.success(), "{}", text(&o.stderr));
        (text(&o.stdout), text(&o.stderr), std::fs::read(out.join("reference/0000.exr")).unwrap())
    };
    let (stdout, _, rendered) = run("first");
    assert!(stdout.contains("1 rendered, 0 from cache"), "{stdout}");
    // The entry, not its lock file (references/KEY.lock).
    let entries: Vec<PathBuf> = std::fs::read_dir(cache.join("references"))
        .unwrap()
        .map(|e| e.unwrap().path())
        .filter(|p| p.extension().is_some_and(|x| x == "ref"))
        .collect();
    assert_eq!(entries.len(), 1, "{entries:?}");
    let entry = &entries[0];
    let good = std::fs::read(entry).unwrap();
    let mut flipped = good.clone();
    let last = flipped.len() - 1;
    flipped[last] ^= 0x40;
    for (name, bytes) in [("truncated", &good[..good.len() / 2]), ("flipped", &flipped[..])] {
        std::fs::write(entry, bytes).unwrap();
        let (stdout, stderr, again) = run(name);
        assert!(stdout.contains("1 rendered, 0 from cache"), "{name}: {stdout}");
        let file = entry.file_name().unwrap().to_str().unwrap();
        assert!(stderr.contains("damaged") && stderr.contains(file), "{name}: {stderr}");
        assert!(again == rendered, "{name}: the rendered-again reference differs");
        assert_eq!(std::fs::read(entry).unwrap(), good, "{name}: the entry is not repaired");
    }
    let (stdout, stderr, cached) = run("cached");
    assert!(stdout.contains("0 rendered, 1 from cache") && !stderr.contains("damaged"), "{stdout}");
    assert!(cached == rendered);
}
