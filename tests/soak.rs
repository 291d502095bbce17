//! Memory stays flat over frames: a long run's resident memory after its last frame against a
//! short run's of the same scenario (the peak is set while pipelines compile at the start, so it
//! hides growth below that spike). What a run must keep per frame is its frames.csv rows (a few hundred bytes per
//! method); images go to disk. The bound is the growth the project allows after warm-up, 16 MiB
//! per 1,000 frames, far above those rows and far below the 1.5 MB per frame that a pipeline
//! recompiled on every bind once cost (Mesa's lavapipe kept each compiled shader).
//!
//! 800 frames between the two runs (1,000 against 200) resolve that bound: it allows 12.5 MiB
//! over them, a growth of 16 KiB a frame, while the recompiled pipeline grew 1.2 GB over as
//! many. The two runs play side by side (separate processes: each one's memory is its own).

use std::path::Path;
use std::process::Command;

const SHORT: u32 = 200;
const LONG: u32 = 1000;
const ALLOWED_PER_1000_FRAMES: f64 = 16.0 * 1024.0 * 1024.0;

fn resident_at_end(dir: &Path, frames: u32) -> (u64, u64) {
    let out = dir.join(format!("run{frames}"));
    let status = Command::new(env!("CARGO_BIN_EXE_flicker"))
        .args(["run", "soak.ron", "--frames", &frames.to_string(), "--quiet", "--out"])
        .arg(&out)
        .arg("--cache-dir")
        .arg(dir.join("cache"))
        .current_dir(dir)
        .status()
        .expect("running flicker");
    assert!(status.success(), "flicker run --frames {frames} failed");
    let manifest: serde_json::Value =
        serde_json::from_slice(&std::fs::read(out.join("manifest.json")).unwrap()).unwrap();
    let memory = &manifest["memory"];
    let resident = memory["resident_bytes_end"].as_u64().expect("resident memory (Linux)");
    let csv = std::fs::metadata(out.join("frames.csv")).unwrap().len();
    (resident, csv)
}

#[test]
fn resident_memory_is_flat_over_frames() {
    let tmp = tempfile::tempdir().unwrap();
    let dir = tmp.path().to_path_buf();
    std::fs::create_dir_all(&dir).unwrap();
    std::fs::write(
        dir.join("soak.ron"),
        "Scenario(scene: Builtin(\"cornell_box\"), resolution: (32, 18), frames: 1, seed: 3,
            methods: [PathTracing(spp: 1), Taa(), HashCache(), SampleCache(), Termination()],
            reference: (spp: 0, frames: None),
            animations: [Flash(entity: \"ceiling_light\", waveform: Sine(frequency: 0.5))])",
    )
    .unwrap();
    let ((short, short_csv), (long, long_csv)) = std::thread::scope(|s| {
        let short = s.spawn(|| resident_at_end(&dir, SHORT));
        let long = s.spawn(|| resident_at_end(&dir, LONG));
        (short.join().unwrap(), long.join().unwrap())
    });
    let growth = long as f64 - short as f64;
    let per_1000 = growth / f64::from(LONG - SHORT) * 1000.0;
    let mib = |b: f64| b / (1024.0 * 1024.0);
    eprintln!(
        "resident after the last frame: {SHORT} frames {:.1} MiB, {LONG} frames {:.1} MiB; {:.2} MiB per 1,000 \
         frames; frames.csv grew by {:.2} MiB",
        mib(short as f64),
        mib(long as f64),
        mib(per_1000),
        mib((long_csv - short_csv) as f64)
    );
    assert!(
        per_1000 < ALLOWED_PER_1000_FRAMES,
        "memory grows by {:.1} MiB per 1,000 frames (allowed {:.0})",
        mib(per_1000),
        mib(ALLOWED_PER_1000_FRAMES)
    );
}
