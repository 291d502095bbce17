//! Hard stops: a run killed with SIGKILL (no handler runs) at random frames resumes to the
//! bytes of an uninterrupted run; a disk that fills while frames, the summary or a reference
//! cache entry are written ends the run with an error naming the file, a manifest that says how
//! far it got, whole files only, and nothing damaged in the cache.
//!
//! A full disk is a file size limit (RLIMIT_FSIZE, `ulimit -f`, in 512-byte blocks under the
//! POSIX shell) with SIGXFSZ ignored, so a write past it fails with EFBIG where a full disk's
//! fails with ENOSPC: at the same write, through the same error path. FLICKER_KILL_SEED replays
//! the kill points of a failure (each run prints its seed).

use std::path::{Path, PathBuf};
use std::process::{Command, Output, Stdio};
use std::time::{Duration, Instant};

mod run_common;
use run_common::results;

fn flicker() -> Command {
    Command::new(env!("CARGO_BIN_EXE_flicker"))
}

/// `flicker` under a file size limit of `blocks` 512-byte blocks, SIGXFSZ ignored (inherited
/// through exec), so an oversized write returns an error as a full disk's does.
fn flicker_limited(blocks: u64) -> Command {
    let mut cmd = Command::new("sh");
    cmd.arg("-c")
        .arg(format!("trap '' XFSZ; ulimit -f {blocks} && exec \"$0\" \"$@\""))
        .arg(env!("CARGO_BIN_EXE_flicker"));
    cmd
}

fn text(bytes: &[u8]) -> String {
    String::from_utf8_lossy(bytes).into_owned()
}

fn json(path: &Path) -> serde_json::Value {
    serde_json::from_str(&std::fs::read_to_string(path).unwrap()).unwrap()
}

fn files(dir: &Path) -> Vec<PathBuf> {
    let mut out = Vec::new();
    for entry in std::fs::read_dir(dir).into_iter().flatten() {
        let p = entry.unwrap().path();
        if p.is_dir() { out.extend(files(&p)) } else { out.push(p) }
    }
    out.sort();
    out
}

/// A folder of its own, removed when the test ends.
fn scratch(name: &str) -> tempfile::TempDir {
    tempfile::Builder::new().prefix(&format!("flicker-{name}-")).tempdir().unwrap()
}

/// The images of a run (relative paths), without the charts.
fn images(run: &Path) -> Vec<PathBuf> {
    files(run)
        .into_iter()
        .filter(|p| p.extension().is_some_and(|e| e == "exr" || e == "png"))
        .filter(|p| !p.starts_with(run.join("charts")))
        .map(|p| p.strip_prefix(run).unwrap().to_path_buf())
        .collect()
}

fn same_bytes(a: &Path, b: &Path, names: &[PathBuf]) {
    for name in names {
        let same = std::fs::read(a.join(name)).unwrap() == std::fs::read(b.join(name)).unwrap();
        assert!(same, "{} differs from the uninterrupted run's", name.display());
    }
}

/// A write's temporary files (`NAME.tmpPID`, metrics::atomic) under `dir`.
fn temporaries(dir: &Path) -> Vec<PathBuf> {
    files(dir)
        .into_iter()
        .filter(|p| p.file_name().is_some_and(|n| n.to_string_lossy().contains(".tmp")))
        .collect()
}

fn run_cmd(mut cmd: Command, scenario: &Path, out: &Path, cache: &Path) -> Command {
    cmd.args(["run", scenario.to_str().unwrap(), "--quiet", "--out"])
        .arg(out)
        .arg("--cache-dir")
        .arg(cache);
    cmd
}

fn resume_cmd(run: &Path, cache: &Path) -> Command {
    let mut cmd = flicker();
    cmd.args(["run", "--quiet", "--resume"]).arg(run).arg("--cache-dir").arg(cache);
    cmd
}

fn ok(o: Output) -> Output {
    assert!(o.status.success(), "stdout: {}\nstderr: {}", text(&o.stdout), text(&o.stderr));
    o
}

/// SplitMix64: the kill points, from a seed printed for replay.
struct Rng(u64);

impl Rng {
    fn below(&mut self, n: u64) -> u64 {
        self.0 = self.0.wrapping_add(0x9e37_79b9_7f4a_7c15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
        (z ^ (z >> 31)) % n
    }
}

const FRAMES: u32 = 8;

/// A moving object, a warm-up frame, `methods` (TAA's history carries state across frames) and
/// a reference at frame `reference`: a resume that skipped the replay would differ.
fn write_scenario(dir: &Path, methods: &[&str], reference: u32, frames: u32) -> PathBuf {
    let scenario = dir.join("moving.ron");
    std::fs::write(
        &scenario,
        format!(
            r#"Scenario(
    scene: Builtin("cornell_box"), resolution: (8, 8), frames: {frames}, warmup_frames: 1, seed: 5,
    max_depth: 2, methods: [{}],
    animations: [Rotate(entity: "tall_box", axis: (0, 1, 0), degrees_per_second: 90)],
    reference: (spp: 2, frames: List([{reference}])),
)"#,
            methods.join(", ")
        ),
    )
    .unwrap();
    scenario
}

/// Starts `cmd`, waits until frames.csv holds `rows` data rows (or the run ends), sleeps
/// `delay` so that the kill lands anywhere in the next frame, and kills it with SIGKILL.
/// Returns whether it was killed (false: it finished first).
fn kill_after(mut cmd: Command, run: &Path, rows: usize, delay: Duration) -> bool {
    let mut child = cmd.stdout(Stdio::null()).stderr(Stdio::piped()).spawn().unwrap();
    let start = Instant::now();
    while std::fs::read_to_string(run.join("frames.csv"))
        .map_or(true, |csv| csv.lines().count() < 1 + rows)
    {
        if let Some(status) = child.try_wait().unwrap() {
            assert!(status.success(), "the run failed: {status}");
            return false;
        }
        assert!(start.elapsed() < Duration::from_secs(120), "no frames after 120 s");
        std::thread::sleep(Duration::from_millis(2));
    }
    std::thread::sleep(delay);
    child.kill().unwrap();
    let status = child.wait().unwrap();
    use std::os::unix::process::ExitStatusExt;
    // It may have finished in the meantime; otherwise SIGKILL ended it.
    status.success() || status.signal() == Some(9)
}

#[test]
fn runs_killed_at_random_frames_resume_to_the_uninterrupted_bytes() {
    let tmp = scratch("sigkill");
    let dir = tmp.path().to_path_buf();
    const METHODS: usize = 2;
    let scenario = write_scenario(&dir, &["PathTracing(spp: 1)", "Taa()"], 3, FRAMES);
    let seed =
        std::env::var("FLICKER_KILL_SEED").ok().and_then(|s| s.parse().ok()).unwrap_or_else(nanos);
    eprintln!("FLICKER_KILL_SEED={seed}");
    let mut rng = Rng(seed);

    let full = dir.join("full");
    ok(run_cmd(flicker(), &scenario, &full, &dir.join("cache_full")).output().unwrap());
    assert_eq!(json(&full.join("manifest.json"))["status"], "complete");

    // Killed twice, at random frames (the second time while resuming), each at a random
    // moment of the frame after; its own cache, so a kill may land in a cache write.
    let (cut, cache) = (dir.join("cut"), dir.join("cache_cut"));
    let first = 1 + rng.below(u64::from(FRAMES) / 2) as usize;
    let second = first + 1 + rng.below(u64::from(FRAMES) / 2 - 1) as usize;
    let delay = |rng: &mut Rng| Duration::from_millis(rng.below(40));
    let d = delay(&mut rng);
    eprintln!("killed after frame {} (+{d:?})", first - 1);
    kill_after(run_cmd(flicker(), &scenario, &cut, &cache), &cut, first * METHODS, d);
    // Whatever the moment, the folder holds whole files: a manifest that parses, and images
    // for every frame frames.csv has.
    let manifest = json(&cut.join("manifest.json"));
    assert!(["running", "complete"].contains(&manifest["status"].as_str().unwrap()), "{manifest}");
    // A kill inside a write leaves its temporary file (`NAME.tmpPID`, cut short); where this
    // one landed between writes, such a file is added as the kill would have left it.
    if temporaries(&cut).is_empty() {
        std::fs::write(cut.join("frames.csv.tmp4194304"), "method,frame,cpu").unwrap();
    }
    let d = delay(&mut rng);
    eprintln!("resumed, killed after frame {} (+{d:?})", second - 1);
    kill_after(resume_cmd(&cut, &cache), &cut, second * METHODS, d);
    // A kill after the last frame may land while the report is written: the manifest says
    // complete and `report.pending` says what is left.
    if json(&cut.join("manifest.json"))["status"] != "complete"
        || cut.join("report.pending").exists()
    {
        ok(resume_cmd(&cut, &cache).output().unwrap());
    }
    assert!(!cut.join("report.pending").exists());
    let manifest = json(&cut.join("manifest.json"));
    assert_eq!(manifest["status"], "complete");
    assert_eq!(results(&cut), results(&full), "frames.csv results differ");
    let list = images(&full);
    assert_eq!(images(&cut), list);
    assert!(list.len() as u32 >= FRAMES * METHODS as u32 * 2, "{} images", list.len());
    same_bytes(&full, &cut, &list);
    // A kill inside a write leaves its temporary file; the resume clears them.
    assert!(temporaries(&cut).is_empty(), "{:?}", temporaries(&cut));
    // The cache holds whole entries only (a killed write may leave its temporary file, which
    // no lookup reads): each passes its checksum.
    assert_whole_entries(&cache, 8, 8);
}

/// The reference cache's files in `dir` but the lock files that stand beside its entries (a
/// lock holds nothing: the OS releases it when its holder dies).
fn cache_files(dir: &Path) -> Vec<PathBuf> {
    files(dir).into_iter().filter(|p| p.extension().is_none_or(|e| e != "lock")).collect()
}

/// Every entry of the reference cache in `dir` decodes with its checksum; nothing else is in
/// it but the temporary files of killed writes and the entries' lock files.
fn assert_whole_entries(dir: &Path, width: u32, height: u32) {
    let cache = frame::reference_cache::ReferenceCache::new(dir);
    let entries: Vec<PathBuf> =
        cache_files(dir).into_iter().filter(|p| !temporaries(dir).contains(p)).collect();
    for entry in &entries {
        assert!(entry.extension().is_some_and(|e| e == "ref"), "{}", entry.display());
        let key = entry.file_stem().unwrap().to_string_lossy();
        let hit = cache.load(&key, width, height);
        assert!(hit.is_some(), "{} is damaged", entry.display());
    }
}

fn nanos() -> u64 {
    std::time::SystemTime::now()
        .duration_since(std::time::UNIX_EPOCH)
        .map_or(1, |d| d.as_nanos() as u64)
}

/// 512-byte blocks that hold `bytes`.
fn blocks(bytes: u64) -> u64 {
    bytes.div_ceil(512)
}

fn size(path: &Path) -> u64 {
    std::fs::metadata(path).unwrap().len()
}

/// Checks a run of `methods` methods stopped by a full disk: the error names the file it could
/// not write, the manifest is whole and says `status` and how far the run got, frames.csv ends
/// at that frame, every image is whole (those of the frame that failed may be there) and
/// equal to `full`'s, and no temporary file is left.
fn check_stopped(
    o: &Output,
    run: &Path,
    full: &Path,
    methods: usize,
    status: &str,
    file: &str,
) -> Option<u32> {
    let stderr = text(&o.stderr);
    assert_eq!(o.status.code(), Some(1), "{stderr}");
    assert!(stderr.contains(file) && stderr.contains("File too large"), "{stderr}");
    let manifest = json(&run.join("manifest.json"));
    assert_eq!(manifest["status"], status, "{manifest}");
    let last = manifest["last_complete_frame"].as_u64().map(|f| f as u32);
    let frames = last.map_or(0, |l| l + 1);
    let rows = results(run);
    assert_eq!(rows.len(), 1 + methods * frames as usize, "{rows:?}");
    assert_eq!(rows[..], results(full)[..rows.len()]);
    // Frames are NNNN.exr and NNNN.png (maps too: their stems end in the frame's digits).
    let frame_of = |p: &PathBuf| -> u32 {
        let stem = p.file_stem().unwrap().to_string_lossy().into_owned();
        let digits: String = stem.chars().rev().take_while(char::is_ascii_digit).collect();
        digits.chars().rev().collect::<String>().parse().unwrap()
    };
    let kept: Vec<PathBuf> = images(full).into_iter().filter(|p| frame_of(p) < frames).collect();
    let written = images(run);
    assert!(kept.iter().all(|p| written.contains(p)), "{kept:?} {written:?}");
    assert!(written.iter().all(|p| frame_of(p) <= frames), "{written:?}");
    same_bytes(full, run, &written);
    assert!(temporaries(run).is_empty(), "{:?}", temporaries(run));
    last
}

#[test]
fn a_full_disk_stops_the_run_cleanly_during_frames_the_summary_and_a_cache_write() {
    let tmp = scratch("full-disk");
    let dir = tmp.path().to_path_buf();
    // Several methods: frames.csv (rewritten whole each frame) outgrows the manifest.
    let methods = ["PathTracing(spp: 1)", "Taa()", "PathTracing(spp: 2)", "HashCache()"];
    // Enough frames that frames.csv (about 500 bytes a frame) outgrows the manifest (6 KB).
    const FULL_DISK_FRAMES: u32 = 24;
    let scenario = write_scenario(&dir, &methods, 3, FULL_DISK_FRAMES);
    let full = dir.join("full");
    ok(run_cmd(flicker(), &scenario, &full, &dir.join("cache_full")).output().unwrap());
    // What the uninterrupted run wrote, by size.
    let manifest = size(&full.join("manifest.json"));
    let largest_image = images(&full).iter().map(|p| size(&full.join(p))).max().unwrap();
    let csv = std::fs::read_to_string(full.join("frames.csv")).unwrap();
    let csv_after = |frame: usize| -> u64 {
        csv.lines().take(1 + methods.len() * (frame + 1)).map(|l| l.len() as u64 + 1).sum()
    };
    let report: Vec<u64> =
        ["summary.json", "report.html"].iter().map(|f| size(&full.join(f))).collect();
    eprintln!(
        "manifest {manifest} B, image {largest_image} B, frames.csv {} B, report {report:?} B",
        csv.len()
    );

    // During frames: frames.csv passes the limit at a frame after the first; the manifest
    // (with an error message of a few hundred bytes) still fits.
    // The limit falls between two frames' tables, clear of both (time columns vary by a few
    // bytes a row from run to run).
    let floor = manifest.max(largest_image) + 1024;
    let (stop, limit) = (2..FULL_DISK_FRAMES as usize)
        .find_map(|f| {
            let limit = blocks(floor.max(csv_after(f - 1) + 100));
            (limit * 512 + 100 < csv_after(f)).then_some((f, limit))
        })
        .expect("frames.csv outgrows the limit: more frames or methods");
    let (run, cache) = (dir.join("frames"), dir.join("cache_frames"));
    let o = run_cmd(flicker_limited(limit), &scenario, &run, &cache).output().unwrap();
    let last = check_stopped(&o, &run, &full, methods.len(), "failed", "frames.csv");
    assert_eq!(last, Some(stop as u32 - 1));
    // What it kept is a run that resumes.
    ok(resume_cmd(&run, &cache).output().unwrap());
    assert_eq!(results(&run), results(&full));

    // The summary and the page: every frame fits, the report does not. The frames are whole
    // and the manifest says so; `flicker report` can write the page once there is room.
    let limit = blocks(manifest.max(largest_image).max(csv.len() as u64) + 1024);
    assert!(report.iter().any(|&s| s > limit * 512), "{report:?} fit in {limit} blocks");
    let run = dir.join("summary");
    let o = run_cmd(flicker_limited(limit), &scenario, &run, &dir.join("cache_summary"))
        .output()
        .unwrap();
    let last = check_stopped(&o, &run, &full, methods.len(), "complete", "writing the report");
    assert_eq!(last, Some(FULL_DISK_FRAMES - 1));
    // `report.pending` says what is left; `--resume` writes it once there is room: the JOD
    // maps and the page, nothing played again.
    assert!(run.join("report.pending").exists(), "{:?}", files(&run));
    let o = ok(resume_cmd(&run, &dir.join("cache_summary")).output().unwrap());
    assert!(text(&o.stdout).contains("wrote the summary"), "{}", text(&o.stdout));
    assert!(!run.join("report.pending").exists() && run.join("report.html").exists());
    assert_eq!(images(&run), images(&full));
    same_bytes(&full, &run, &images(&full));

    // A reference cache entry over the limit: at 32x32 every entry and image is, and the
    // reference of frame 0 is stored before frame 0's images are written.
    let scenario = write_scenario(&dir, &methods[..1], 0, 2);
    let (run, cache) = (dir.join("cache_write"), dir.join("cache_big"));
    let mut cmd = run_cmd(flicker_limited(blocks(manifest + 1024)), &scenario, &run, &cache);
    let o = cmd.args(["--resolution", "32x32"]).output().unwrap();
    let stderr = text(&o.stderr);
    assert_eq!(o.status.code(), Some(1), "{stderr}");
    assert!(stderr.contains("references") && stderr.contains("File too large"), "{stderr}");
    let manifest = json(&run.join("manifest.json"));
    assert_eq!(manifest["status"], "failed");
    assert!(manifest["last_complete_frame"].is_null(), "{manifest}");
    assert!(images(&run).is_empty() && temporaries(&run).is_empty(), "{:?}", files(&run));
    // Nothing in the cache but the entry's lock: an entry over the limit cannot be whole, and
    // its temporary file is gone.
    assert!(cache_files(&cache).is_empty(), "{:?}", files(&cache));
}
