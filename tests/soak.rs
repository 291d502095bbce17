//! Memory stays flat over frames: a run's memory after its last frame against its own after 256
//! frames, read within one process (`memory.by_frame` in manifest.json), both the resident
//! memory and the heap in use. Two processes of the same scenario end tens of MiB apart in
//! resident memory, so growth is not read across runs; and resident memory alone hides a
//! leak while freed pages are reused (a build keeping 24 KiB a frame grew it by 1.4 MiB over
//! 744 frames, as much as one without). The peak is set while pipelines compile at the start,
//! so the first reading is taken well after it.
//!
//! What a run must keep per frame is its frames.csv rows (a few hundred bytes per method);
//! images go to disk. The bound is the growth the project allows after warm-up, 16 MiB per
//! 1,000 frames, far above those rows and far below the 1.5 MB per frame that a pipeline
//! recompiled on every bind once cost (Mesa's lavapipe kept each compiled shader): over the 744
//! frames between the readings it allows 11.9 MiB, a growth of 16 KiB a frame.

use std::process::Command;

const FRAMES: u32 = 1000;
const SETTLED: u32 = 256;
const ALLOWED_PER_1000_FRAMES: f64 = 16.0 * 1024.0 * 1024.0;

#[test]
fn resident_memory_is_flat_over_frames() {
    let tmp = tempfile::tempdir().unwrap();
    let dir = tmp.path();
    std::fs::write(
        dir.join("soak.ron"),
        "Scenario(scene: Builtin(\"cornell_box\"), resolution: (32, 18), frames: 1, seed: 3,
            methods: [PathTracing(spp: 1), Taa(), HashCache(), SampleCache(), Termination()],
            reference: (spp: 0, frames: None),
            animations: [Flash(entity: \"ceiling_light\", waveform: Sine(frequency: 0.5))])",
    )
    .unwrap();
    let out = dir.join("run");
    let status = Command::new(env!("CARGO_BIN_EXE_flicker"))
        .args(["run", "soak.ron", "--frames", &FRAMES.to_string(), "--quiet", "--out"])
        .arg(&out)
        .arg("--cache-dir")
        .arg(dir.join("cache"))
        .current_dir(dir)
        .status()
        .expect("running flicker");
    assert!(status.success(), "flicker run --frames {FRAMES} failed");
    let manifest: serde_json::Value =
        serde_json::from_slice(&std::fs::read(out.join("manifest.json")).unwrap()).unwrap();
    let samples = manifest["memory"]["by_frame"].as_array().expect("memory.by_frame").clone();
    let at = |frames: u32, what: &str| {
        let sample = samples
            .iter()
            .find(|s| s["frames"] == frames)
            .unwrap_or_else(|| panic!("no memory sample after {frames} frames: {samples:?}"));
        sample[what].as_u64().unwrap_or_else(|| panic!("no {what} (Linux with glibc)"))
    };
    let mib = |b: f64| b / (1024.0 * 1024.0);
    let curve = |what: &str| {
        let values: Vec<String> = samples
            .iter()
            .map(|s| format!("{}: {:.1}", s["frames"], mib(s[what].as_f64().unwrap_or(f64::NAN))))
            .collect();
        values.join(", ")
    };
    eprintln!("MiB after frames played, resident: {}", curve("resident_bytes"));
    eprintln!("MiB after frames played, heap in use: {}", curve("heap_bytes"));
    // Resident memory catches what the allocator does not see (pages mapped by the driver, a
    // shader compiler's code); the heap in use catches a leak that freed pages would hide.
    for what in ["resident_bytes", "heap_bytes"] {
        let growth = at(FRAMES, what) as f64 - at(SETTLED, what) as f64;
        let per_1000 = growth / f64::from(FRAMES - SETTLED) * 1000.0;
        eprintln!("{what}: {:.2} MiB per 1,000 frames after {SETTLED}", mib(per_1000));
        assert!(
            per_1000 < ALLOWED_PER_1000_FRAMES,
            "{what} grows by {:.1} MiB per 1,000 frames after {SETTLED} (allowed {:.0})",
            mib(per_1000),
            mib(ALLOWED_PER_1000_FRAMES)
        );
    }
}
