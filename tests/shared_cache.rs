//! Runs that share a reference cache render each reference once: several `flicker run`
//! processes of one tiny scenario, started at once on one cache folder, each say whether they
//! rendered or reused its reference, and exactly one rendered it.

use std::path::PathBuf;
use std::process::{Command, Stdio};

/// Four processes on a 2-core machine: more than the cores, so some wait on the lock.
const RUNS: usize = 4;

#[test]
fn concurrent_runs_render_a_shared_reference_once() {
    let tmp = tempfile::Builder::new().prefix("flicker-shared-cache-").tempdir().unwrap();
    let dir = tmp.path().to_path_buf();
    let scenario = dir.join("tiny.ron");
    // One recorded frame with a reference: 16x16 at 64 spp takes long enough (about a second
    // on lavapipe) that every process looks the entry up before the first has stored it.
    std::fs::write(
        &scenario,
        "Scenario(scene: Builtin(\"cornell_box\"), resolution: (16, 16), frames: 1,\n  methods: [PathTracing(spp: 1)],\n  reference: (spp: 64, frames: Every(1)),\n)\n",
    )
    .unwrap();
    let cache = dir.join("cache");
    let outs: Vec<PathBuf> = (0..RUNS).map(|i| dir.join(format!("run_{i}"))).collect();
    let children: Vec<_> = outs
        .iter()
        .map(|out| {
            Command::new(env!("CARGO_BIN_EXE_flicker"))
                .arg("run")
                .arg(&scenario)
                .arg("--quiet")
                .arg("--out")
                .arg(out)
                .arg("--cache-dir")
                .arg(&cache)
                .stdout(Stdio::piped())
                .stderr(Stdio::piped())
                .spawn()
                .unwrap()
        })
        .collect();
    let mut rendered = 0;
    for child in children {
        let o = child.wait_with_output().unwrap();
        let stdout = String::from_utf8_lossy(&o.stdout).into_owned();
        assert!(o.status.success(), "{stdout}\n{}", String::from_utf8_lossy(&o.stderr));
        // "wrote DIR (1 frames; references: R rendered, C from cache)"
        if stdout.contains("references: 1 rendered, 0 from cache") {
            rendered += 1;
        } else {
            assert!(stdout.contains("references: 0 rendered, 1 from cache"), "{stdout}");
        }
    }
    assert_eq!(rendered, 1, "exactly one of {RUNS} runs renders the shared reference");
    // Every run measured against the same reference: their FLIP columns agree.
    let flip = |out: &PathBuf| {
        let csv = std::fs::read_to_string(out.join("frames.csv")).unwrap();
        let rows: Vec<Vec<String>> =
            csv.lines().map(|l| l.split(',').map(String::from).collect()).collect();
        let c = rows[0].iter().position(|h| h == "flip").expect("a flip column");
        rows[1][c].clone()
    };
    let first = flip(&outs[0]);
    assert!(outs.iter().all(|o| flip(o) == first));
}
