//! Interrupted runs: SIGINT after a few frames leaves a run marked incomplete, and
//! `flicker run --resume` finishes it with the frames of an uninterrupted run.

use std::path::{Path, PathBuf};
use std::process::{Command, Output, Stdio};
use std::time::{Duration, Instant};

mod run_common;
use run_common::results;

fn flicker() -> Command {
    Command::new(env!("CARGO_BIN_EXE_flicker"))
}

fn text(bytes: &[u8]) -> String {
    String::from_utf8_lossy(bytes).into_owned()
}

fn json(path: &Path) -> serde_json::Value {
    serde_json::from_str(&std::fs::read_to_string(path).unwrap()).unwrap()
}

fn files(dir: &Path) -> Vec<PathBuf> {
    let mut out = Vec::new();
    for entry in std::fs::read_dir(dir).unwrap() {
        let p = entry.unwrap().path();
        if p.is_dir() { out.extend(files(&p)) } else { out.push(p) }
    }
    out.sort();
    out
}

fn run_args(cmd: &mut Command, scenario: &Path, out: &Path, cache: &Path) {
    cmd.args(["run", scenario.to_str().unwrap(), "--quiet", "--out"])
        .arg(out)
        .arg("--cache-dir")
        .arg(cache);
}

/// `flicker run --resume RUN` with the reference cache `cache`.
fn resume(run: &Path, cache: &Path) -> Output {
    flicker()
        .arg("run")
        .arg("--resume")
        .arg(run)
        .arg("--quiet")
        .arg("--cache-dir")
        .arg(cache)
        .output()
        .unwrap()
}

/// A reference cache in `dir` that cannot store references (`references` is a file): a run
/// stops with an error at its first reference frame.
fn references_blocked(dir: &Path) -> PathBuf {
    let cache = dir.join("cache");
    std::fs::create_dir_all(&cache).unwrap();
    std::fs::write(cache.join("references"), "in the way").unwrap();
    cache
}

/// Each of `names` (relative paths) byte-identical in `full` and `cut`.
fn assert_same_bytes(full: &Path, cut: &Path, names: &[PathBuf]) {
    for name in names {
        let (a, b) =
            (std::fs::read(full.join(name)).unwrap(), std::fs::read(cut.join(name)).unwrap());
        assert!(a == b, "{} differs from the uninterrupted run's", name.display());
    }
}

fn ok(o: Output) -> Output {
    assert!(o.status.success(), "stdout: {}\nstderr: {}", text(&o.stdout), text(&o.stderr));
    o
}

#[test]
fn an_interrupted_run_says_so_and_resumes_to_the_uninterrupted_frames() {
    let tmp = tempfile::tempdir().unwrap();
    let dir = tmp.path().to_path_buf();
    std::fs::create_dir_all(&dir).unwrap();
    let cache = dir.join("cache");
    // Methods with state carried across frames (TAA's history, the hash cache's cells), a
    // moving object and warm-up frames: a resume that skipped the replay would differ.
    let scenario = dir.join("moving.ron");
    let frames = 30;
    std::fs::write(
        &scenario,
        format!(
            r#"Scenario(
    scene: Builtin("cornell_box"), resolution: (16, 9), frames: {frames}, warmup_frames: 2, seed: 3,
    max_depth: 3, methods: [PathTracing(spp: 1), Taa(), HashCache()],
    animations: [Rotate(entity: "tall_box", axis: (0, 1, 0), degrees_per_second: 90)],
    reference: (spp: 4, frames: Every(7)),
)"#
        ),
    )
    .unwrap();

    // Cut short: SIGINT once three frames are on disk.
    let cut = dir.join("cut");
    let mut cmd = flicker();
    run_args(&mut cmd, &scenario, &cut, &cache);
    let mut child = cmd.stdout(Stdio::piped()).stderr(Stdio::piped()).spawn().unwrap();
    let start = Instant::now();
    let methods = 3;
    while std::fs::read_to_string(cut.join("frames.csv"))
        .map_or(true, |csv| csv.lines().count() < 1 + 3 * methods)
    {
        assert!(child.try_wait().unwrap().is_none(), "the run ended before it was interrupted");
        assert!(start.elapsed() < Duration::from_secs(120), "no frames after 120 s");
        std::thread::sleep(Duration::from_millis(10));
    }
    // The shell's own `kill` (a minimal Debian may lack /usr/bin/kill).
    let kill =
        Command::new("sh").arg("-c").arg(format!("kill -INT {}", child.id())).status().unwrap();
    assert!(kill.success());
    let o = child.wait_with_output().unwrap();
    let stderr = text(&o.stderr);
    assert_eq!(o.status.code(), Some(130), "{stderr}");
    assert!(stderr.contains("--resume"), "{stderr}");
    let manifest = json(&cut.join("manifest.json"));
    assert_eq!(manifest["status"], "interrupted");
    let last = manifest["last_complete_frame"].as_u64().expect("a last complete frame") as u32;
    assert!((2..frames - 1).contains(&last), "stopped at frame {last}");
    // The frame on hand was finished: frames.csv and the images end at the same frame.
    let rows = results(&cut);
    assert_eq!(rows.len() as u32, 1 + methods as u32 * (last + 1));
    assert!(cut.join(format!("frames/taa/{last:04}.exr")).exists());
    assert!(!cut.join(format!("frames/taa/{:04}.exr", last + 1)).exists());
    let page = std::fs::read_to_string(cut.join("report.html")).unwrap();
    assert!(page.contains("Incomplete run"), "the report must say the run is incomplete");
    // No write's temporary file (`NAME.tmpPID`, metrics::atomic) is left; the file names are
    // read, not the paths (tempfile's folders are named `.tmpXXXXXX`).
    let temporaries: Vec<_> = files(&cut)
        .into_iter()
        .filter(|p| p.file_name().is_some_and(|n| n.to_string_lossy().contains(".tmp")))
        .collect();
    assert!(temporaries.is_empty(), "{temporaries:?}");

    // The whole run, uninterrupted.
    let full = dir.join("full");
    let mut cmd = flicker();
    run_args(&mut cmd, &scenario, &full, &cache);
    ok(cmd.output().unwrap());
    assert_eq!(json(&full.join("manifest.json"))["status"], "complete");
    assert!(!std::fs::read_to_string(full.join("report.html")).unwrap().contains("Incomplete"));

    // A copy whose written results disagree with the replay is refused, at the row.
    let forged = dir.join("forged");
    std::fs::create_dir_all(&forged).unwrap();
    for f in ["manifest.json", "frames.csv"] {
        std::fs::copy(cut.join(f), forged.join(f)).unwrap();
    }
    let csv = std::fs::read_to_string(forged.join("frames.csv")).unwrap();
    let mut rows: Vec<Vec<String>> =
        csv.lines().map(|l| l.split(',').map(str::to_string).collect()).collect();
    let rays = rows[0].iter().position(|h| h == "rays").unwrap();
    let counted: u64 = rows[2][rays].parse().unwrap();
    rows[2][rays] = (counted + 1).to_string();
    let forged_csv: Vec<String> = rows.iter().map(|r| r.join(",")).collect();
    std::fs::write(forged.join("frames.csv"), forged_csv.join("\n") + "\n").unwrap();
    let o = resume(&forged, &cache);
    let stderr = text(&o.stderr);
    assert!(!o.status.success());
    assert!(stderr.contains("frames.csv:3: rays of") && stderr.contains("replay"), "{stderr}");

    // Resumed: the same results and byte-identical images as the uninterrupted run.
    let o = ok(resume(&cut, &cache));
    assert!(text(&o.stdout).contains("wrote"), "{}", text(&o.stdout));
    let manifest = json(&cut.join("manifest.json"));
    assert_eq!(manifest["status"], "complete");
    assert_eq!(manifest["last_complete_frame"], frames - 1);
    assert_eq!(manifest["resumed"][0]["from_frame"], last + 1);
    assert_eq!(results(&cut), results(&full), "frames.csv results differ");
    let images = |run: &Path| -> Vec<PathBuf> {
        files(run)
            .into_iter()
            .filter(|p| p.extension().is_some_and(|e| e == "exr" || e == "png"))
            .filter(|p| !p.starts_with(run.join("charts")))
            .map(|p| p.strip_prefix(run).unwrap().to_path_buf())
            .collect()
    };
    let list = images(&full);
    assert_eq!(images(&cut), list);
    assert!(list.len() > 100, "{} images", list.len());
    assert_same_bytes(&full, &cut, &list);
    assert!(!std::fs::read_to_string(cut.join("report.html")).unwrap().contains("Incomplete run"));

    // Nothing is left to resume; a folder that is no run is named.
    let o = flicker().arg("run").arg("--resume").arg(&cut).arg("--quiet").output().unwrap();
    assert!(text(&o.stderr).contains("complete; nothing to resume"), "{}", text(&o.stderr));
    let o = flicker().arg("run").arg("--resume").arg(&dir).arg("--quiet").output().unwrap();
    assert!(
        !o.status.success() && text(&o.stderr).contains("manifest.json"),
        "{}",
        text(&o.stderr)
    );
    let o = flicker().args(["run", "--resume"]).arg(&cut).args(["--frames", "3"]).output().unwrap();
    assert!(!o.status.success() && text(&o.stderr).contains("--frames"), "{}", text(&o.stderr));
}

#[test]
fn a_run_stopped_by_an_error_is_marked_failed_and_resumes_once_it_is_fixed() {
    let tmp = tempfile::tempdir().unwrap();
    let dir = tmp.path().to_path_buf();
    std::fs::create_dir_all(&dir).unwrap();
    let scenario = dir.join("late_reference.ron");
    std::fs::write(
        &scenario,
        r#"Scenario(scene: Builtin("cornell_box"), resolution: (8, 8), frames: 5, seed: 1, max_depth: 2,
    methods: [Taa()], reference: (spp: 2, frames: List([3])))"#,
    )
    .unwrap();
    // The reference cache cannot store frame 3's reference: `references` is a file.
    let cache = references_blocked(&dir);
    let run = dir.join("run");
    let mut cmd = flicker();
    run_args(&mut cmd, &scenario, &run, &cache);
    let o = cmd.output().unwrap();
    let stderr = text(&o.stderr);
    assert_eq!(o.status.code(), Some(1), "{stderr}");
    assert!(stderr.contains("reference of frame 3") || stderr.contains("references"), "{stderr}");
    let manifest = json(&run.join("manifest.json"));
    assert_eq!(manifest["status"], "failed");
    assert_eq!(manifest["last_complete_frame"], 2);
    assert!(manifest["error"].as_str().is_some_and(|e| e.contains("references")), "{manifest}");
    assert_eq!(results(&run).len(), 1 + 3, "frames 0 to 2 in frames.csv");
    let page = std::fs::read_to_string(run.join("report.html")).unwrap();
    assert!(page.contains("Incomplete run") && page.contains("failed"));

    std::fs::remove_file(cache.join("references")).unwrap();
    ok(resume(&run, &cache));
    let manifest = json(&run.join("manifest.json"));
    assert_eq!(manifest["status"], "complete");
    assert!(manifest.get("error").is_none(), "{manifest}");
    assert_eq!(results(&run).len(), 1 + 5);
    assert!(run.join("reference/0003.exr").exists() && run.join("frames/taa/0004.exr").exists());
}

#[test]
fn runs_of_the_caches_resume_to_the_uninterrupted_frames() {
    // The termination cache (new keys contending for 128 slots) and the sample cache with
    // adaptive shading (a camera backing away: pixels receive more samples than they keep)
    // make contended choices on the GPU every frame; a resume replays them and must meet the
    // same rows. The run stops at frame 3 (its reference cannot be stored), then resumes.
    let tmp = tempfile::tempdir().unwrap();
    let dir = tmp.path().to_path_buf();
    std::fs::create_dir_all(&dir).unwrap();
    let scenario = dir.join("caches.ron");
    std::fs::write(
        &scenario,
        r#"Scenario(scene: Builtin("courtyard"), resolution: (32, 18), frames: 6, seed: 1, max_depth: 2,
    methods: [
        Termination(rule: VarianceBounding(t: 1.0, relative: true), capacity: 128, store_probability: 1.0, warmup_frames: 2),
        SampleCache(retrace: Adaptive, shading: Adaptive, shading_rate: 0.7),
    ],
    reference: (spp: 2, frames: List([3])),
    animations: [CameraPath(keys: [
        (frame: 0.0, position: (0.0, 1.7, 1.5), target: (1.5, 1.6, -3.5)),
        (frame: 6.0, position: (-3.0, 1.7, 4.0), target: (1.5, 1.6, -3.5)),
    ])])"#,
    )
    .unwrap();
    let cache = references_blocked(&dir);
    let cut = dir.join("cut");
    let mut cmd = flicker();
    run_args(&mut cmd, &scenario, &cut, &cache);
    let o = cmd.output().unwrap();
    assert_eq!(o.status.code(), Some(1), "{}", text(&o.stderr));
    assert_eq!(json(&cut.join("manifest.json"))["last_complete_frame"], 2);
    std::fs::remove_file(cache.join("references")).unwrap();
    ok(resume(&cut, &cache));
    let full = dir.join("full");
    let mut cmd = flicker();
    run_args(&mut cmd, &scenario, &full, &cache);
    ok(cmd.output().unwrap());
    assert_eq!(results(&cut), results(&full), "frames.csv results differ");
    let exrs: Vec<PathBuf> = files(&full)
        .into_iter()
        .filter(|p| p.extension().is_some_and(|e| e == "exr"))
        .map(|p| p.strip_prefix(&full).unwrap().to_path_buf())
        .collect();
    assert!(exrs.len() >= 12, "{} images", exrs.len());
    assert_same_bytes(&full, &cut, &exrs);
}
