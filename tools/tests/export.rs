//! `flicker export`: every exported .glb passes the Khronos glTF validator with no errors; flicker
//! plays its own export (the package's scenario.ron: the .glb as a glTF scene, its animations
//! included) and renders the original's references within their standard errors; a package
//! with its references and inputs is measured by `flicker measure --scenario`, and one missing a
//! frame is refused naming the file and frame.

use std::path::{Path, PathBuf};
use std::process::Command;

use playback::play::{self, Overrides, RunOptions, RunSpec};
use sim::{ReferenceFrames, Scenario};
use statrs::distribution::{ContinuousCDF, StudentsT};
use tools::export::{ExportOptions, export};

fn root() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).parent().unwrap().to_path_buf()
}

fn temp(name: &str) -> tempfile::TempDir {
    tempfile::Builder::new().prefix(&format!("flicker-export-{name}-")).tempdir().unwrap()
}

const ROUND_TRIP: &str = "tools/tests/data/export_round_trip.ron";

fn scene_only(scenario: &Path, out: &Path, frames: Option<u32>) -> PathBuf {
    export(&ExportOptions {
        scenario: scenario.to_path_buf(),
        out: out.to_path_buf(),
        overrides: Overrides { frames, resolution: Some((32, 18)), ..Default::default() },
        scene_only: true,
        ..Default::default()
    })
    .unwrap_or_else(|e| panic!("{}: {e:#}", scenario.display()));
    out.join("scene.glb")
}

/// The Khronos validator's report of `glb` (scripts/gltf-validate.cjs). Missing, it fails the
/// test: scripts/setup-tests.sh installs it, and CI runs that.
fn validate(glb: &Path) -> serde_json::Value {
    let out = Command::new("node")
        .arg(root().join("scripts/gltf-validate.cjs"))
        .arg(glb)
        .output()
        .expect("node runs (scripts/setup-tests.sh installs Node.js and the glTF validator)");
    assert!(
        out.status.success(),
        "the Khronos glTF validator did not run on {}: {} (scripts/setup-tests.sh installs it)",
        glb.display(),
        String::from_utf8_lossy(&out.stderr)
    );
    serde_json::from_slice(&out.stdout).expect("the validator prints a JSON report")
}

/// Every shipped scenario whose scene the export holds (not media, not subsurface), and the
/// round-trip scenario: the validator finds no error.
#[test]
fn every_exported_glb_passes_the_khronos_validator() {
    let tmp = temp("validator");
    let dir = tmp.path().to_path_buf();
    let scenarios = [
        ROUND_TRIP,
        "scenarios/showcase.ron",
        "scenarios/boids.ron",
        "scenarios/camera_path.ron",
        "scenarios/events.ron",
        "scenarios/flash_sine.ron",
        "scenarios/flash_square.ron",
        "scenarios/keyframes.ron",
        "scenarios/strobe.ron",
        "scenarios/gltf_test_scene.ron",
        "scenarios/light_rotation_corridor.ron",
        "scenarios/rotating_cone.ron",
    ];
    let mut failures = Vec::new();
    for (i, s) in scenarios.iter().enumerate() {
        let glb = scene_only(&root().join(s), &dir.join(i.to_string()), Some(6));
        let report = validate(&glb);
        let errors = report["issues"]["numErrors"].as_u64().expect("numErrors");
        if errors > 0 {
            let messages: Vec<&serde_json::Value> = report["issues"]["messages"]
                .as_array()
                .unwrap()
                .iter()
                .filter(|m| m["severity"] == 0)
                .take(5)
                .collect();
            failures.push(format!("{s}: {errors} errors, e.g. {messages:?}"));
        }
        // Something the validator would only skip: the file must carry what it claims.
        assert!(report["info"]["animationCount"].as_u64().is_some(), "{s}: {report}");
    }
    assert!(failures.is_empty(), "{}", failures.join("\n"));
}

/// References of `scenario` (as given, or as its export's scenario.ron) at `frames`, one image
/// per seed: [seed][frame] -> RGB pixels.
fn references(
    scenario: Scenario,
    frames: &[u32],
    seeds: &[u64],
    dir: &Path,
) -> Vec<Vec<Vec<[f32; 3]>>> {
    let mut out = Vec::new();
    for &seed in seeds {
        let mut s = scenario.clone();
        s.seed = seed;
        s.reference.frames = ReferenceFrames::List(frames.to_vec());
        s.output = dir.join(format!("{}_{seed}", s.name));
        let spec = RunSpec::from_scenario(s, &Overrides::default()).unwrap();
        let summary = play::run_spec(
            &spec,
            &RunOptions {
                scenario: spec.scenario.origin.clone(),
                overrides: Overrides::default(),
                cache_dir: Some(dir.join("cache")),
                progress: false,
            },
        )
        .unwrap();
        let folder = frame::run_folder::RunFolder::new(&summary.folder);
        out.push(
            frames
                .iter()
                .map(|&f| metrics::load_image(folder.reference(f, "exr")).unwrap().rgb)
                .collect(),
        );
    }
    out
}

/// Block z-test of two sets of references (independent seeds on each side), block by block:
/// the block's mean difference over its pixels, against the standard error from the pixels'
/// sample variances over the seeds (pixels are independent estimates, so their variances add);
/// its degrees of freedom by Welch-Satterthwaite; Bonferroni over every block, channel and
/// frame at a family-wise false-alarm rate of 1e-3. Returns the failures.
fn block_z_test(
    a: &[Vec<Vec<[f32; 3]>>],
    b: &[Vec<Vec<[f32; 3]>>],
    (w, h): (usize, usize),
    block: (usize, usize),
    frames: &[u32],
) -> Vec<String> {
    let (ka, kb) = (a.len() as f64, b.len() as f64);
    let blocks = (w / block.0) * (h / block.1);
    let tests = (blocks * 3 * frames.len()) as f64;
    let alpha = 1e-3 / tests;
    let mut failures = Vec::new();
    for (fi, frame) in frames.iter().enumerate() {
        for by in 0..h / block.1 {
            for bx in 0..w / block.0 {
                for c in 0..3 {
                    let (mut diff, mut var, mut var2_over_dof, mut n) = (0.0, 0.0, 0.0, 0.0);
                    for y in by * block.1..(by + 1) * block.1 {
                        for x in bx * block.0..(bx + 1) * block.0 {
                            let p = y * w + x;
                            let va: Vec<f64> = a.iter().map(|s| s[fi][p][c] as f64).collect();
                            let vb: Vec<f64> = b.iter().map(|s| s[fi][p][c] as f64).collect();
                            let mean = |v: &[f64]| v.iter().sum::<f64>() / v.len() as f64;
                            let svar = |v: &[f64], m: f64| {
                                v.iter().map(|x| (x - m).powi(2)).sum::<f64>()
                                    / (v.len() as f64 - 1.0)
                            };
                            let (ma, mb) = (mean(&va), mean(&vb));
                            let (sa, sb) = (svar(&va, ma) / ka, svar(&vb, mb) / kb);
                            diff += ma - mb;
                            var += sa + sb;
                            var2_over_dof += sa * sa / (ka - 1.0) + sb * sb / (kb - 1.0);
                            n += 1.0;
                        }
                    }
                    let (d, se) = (diff / n, var.sqrt() / n);
                    let scale = 1e-6;
                    if se == 0.0 {
                        if d.abs() > scale {
                            failures.push(format!(
                                "frame {frame} block ({bx}, {by}) channel {c}: difference {d:.3e} without noise"
                            ));
                        }
                        continue;
                    }
                    let dof = (var * var / var2_over_dof).max(1.0);
                    let critical =
                        StudentsT::new(0.0, 1.0, dof).unwrap().inverse_cdf(1.0 - alpha / 2.0);
                    let t = d / se;
                    if t.abs() > critical {
                        failures.push(format!(
                            "frame {frame} block ({bx}, {by}) channel {c}: t = {t:.1} (difference {d:.4}, standard error {se:.4}, {dof:.0} dof; critical {critical:.1})"
                        ));
                    }
                }
            }
        }
    }
    failures
}

/// flicker plays its own export and renders the original's references at the first frame, the
/// event's frame and the last, within their standard errors: boids, a flashing light
/// (KHR_animation_pointer), keyframes, a camera path with a changing field of view (pointer) and
/// events (a turned light, a moved object, a changed material: pointer) all come back.
#[test]
fn flicker_plays_its_export_and_renders_the_same_references() {
    let start = std::time::Instant::now();
    let tmp = temp("round_trip");
    let dir = tmp.path().to_path_buf();
    let original = Scenario::load(&root().join(ROUND_TRIP)).unwrap();
    let package = dir.join("package");
    scene_only(&original.origin, &package, None);
    let exported = Scenario::load(&package.join("scenario.ron")).unwrap();
    assert_eq!((exported.frames, exported.time_step), (original.frames, original.time_step));
    let frames = [0, 2, 4];
    let a = references(original, &frames, &[1, 2, 3], &dir);
    let b = references(exported, &frames, &[11, 12, 13], &dir);
    let failures = block_z_test(&a, &b, (32, 18), (4, 3), &frames);
    assert!(failures.is_empty(), "{} blocks differ:\n{}", failures.len(), failures.join("\n"));
    eprintln!("round trip: {:.1} s", start.elapsed().as_secs_f64());
}

/// A package with its references and a denoiser's inputs: every file at the scenario's size, the
/// 1-spp radiance measured against the references with the package's frame rate and events (what
/// `flicker measure --scenario` reads), and a package missing a reference frame refused, naming
/// the file and frame, before anything is written.
#[test]
fn a_package_is_measured_and_one_missing_a_frame_is_refused() {
    let tmp = temp("package");
    let dir = tmp.path().to_path_buf();
    let package = dir.join("package");
    export(&ExportOptions {
        scenario: root().join(ROUND_TRIP),
        out: package.clone(),
        overrides: Overrides { frames: Some(3), ..Default::default() },
        reference_spp: Some(4),
        cache_dir: Some(dir.join("cache")),
        ..Default::default()
    })
    .unwrap();
    for k in 0..3 {
        let name = format!("{k:04}.exr");
        let mut files = vec![package.join("reference").join(&name)];
        files.extend(
            tools::export::INPUTS.iter().map(|i| package.join("inputs").join(i).join(&name)),
        );
        for f in files {
            let (w, h, _) = frame::output::read_exr(&f).unwrap_or_else(|e| panic!("{e:#}"));
            assert_eq!((w, h), (32, 18), "{}", f.display());
        }
        let record: serde_json::Value = serde_json::from_str(
            &std::fs::read_to_string(package.join("frames").join(format!("{k:04}.json"))).unwrap(),
        )
        .unwrap();
        assert_eq!(record["camera"]["view"].as_array().unwrap().len(), 16);
        assert_eq!(record["lights"].as_array().unwrap().len(), 2, "the sun and the lamp");
        assert_eq!(record["events"].as_array().unwrap().len(), if k == 2 { 3 } else { 0 });
    }
    let p = tools::export::Package::read(&package).unwrap();
    assert_eq!((p.frames, p.events.len()), (3, 3));
    assert!((p.fps - 30.0).abs() < 1e-3, "{}", p.fps);
    let out = dir.join("measured");
    let opts = tools::measure::MeasureOptions {
        reference: p.reference.clone(),
        tests: vec![("noisy".into(), package.join("inputs/radiance"))],
        motion: vec![("noisy".into(), package.join("inputs/motion"))],
        fps: p.fps,
        events: p.events.iter().map(|e| e.0).collect(),
        labels: p.events.iter().map(|e| e.1.clone()).collect(),
        timings: Vec::new(),
        out: out.clone(),
        cvvdp: p.cvvdp.clone(),
        smape_epsilon: p.smape_epsilon,
    };
    tools::measure::measure(&opts).unwrap();
    let csv = std::fs::read_to_string(out.join("frames.csv")).unwrap();
    assert_eq!(csv.lines().count(), 4, "{csv}");

    std::fs::remove_file(package.join("reference/0001.exr")).unwrap();
    let e = format!("{:#}", tools::export::Package::read(&package).unwrap_err());
    assert!(e.contains("reference/0001.exr") && e.contains("frame 1 is missing"), "{e}");
}
