//! `flicker measure`: a flicker run's frames measured again from disk give the run's own
//! metrics (the round trip), and bad input is refused naming the file and frame, with nothing
//! written. The round trip is exact, not within a tolerance: a run records its frames as f32
//! EXR (lossless), and measure reads them back through the same metric code, so every number
//! comes from the same floats in the same order.

use std::path::{Path, PathBuf};

use metrics::CvvdpSettings;
use playback::play::{self, Overrides, RunOptions};
use tools::measure::{MeasureOptions, measure};

fn temp(name: &str) -> tempfile::TempDir {
    tempfile::Builder::new().prefix(&format!("flicker-measure-{name}-")).tempdir().unwrap()
}

fn options(reference: &Path, tests: &[(&str, PathBuf)], out: PathBuf) -> MeasureOptions {
    MeasureOptions {
        reference: reference.to_path_buf(),
        tests: tests.iter().map(|(n, d)| (n.to_string(), d.clone())).collect(),
        motion: Vec::new(),
        fps: 30.0,
        events: Vec::new(),
        labels: Vec::new(),
        timings: Vec::new(),
        out,
        cvvdp: CvvdpSettings::default(),
        smape_epsilon: 0.01,
    }
}

/// The image metrics of frames.csv and summary.json (timings differ: measure has none).
const METRICS: [&str; 7] =
    ["smape", "smape_reprojected", "disoccluded", "flip", "mse", "rel_mse", "psnr"];

/// frames.csv's metric columns, row by row: (method, frame, column) -> cell text.
fn metric_cells(run: &Path) -> Vec<(String, String, String, String)> {
    let text = std::fs::read_to_string(run.join("frames.csv")).unwrap();
    let mut lines = text.lines();
    let header: Vec<&str> = lines.next().unwrap().split(',').collect();
    let wanted = METRICS;
    lines
        .flat_map(|l| {
            let cells: Vec<&str> = l.split(',').collect();
            let header = header.clone();
            wanted.iter().map(move |w| {
                let i = header.iter().position(|h| h == w).unwrap();
                (cells[0].to_string(), cells[1].to_string(), w.to_string(), cells[i].to_string())
            })
        })
        .collect()
}

/// summary.json of `method`: its JOD per window, and its image metrics' means per window.
fn summary_metrics(run: &Path, method: &str) -> (serde_json::Value, Vec<(String, String, f64)>) {
    let s: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(run.join("summary.json")).unwrap()).unwrap();
    let m = s["methods"].as_array().unwrap().iter().find(|m| m["method"] == method).unwrap();
    assert!(m["jod"]["overall"].is_f64(), "no overall JOD for {method}: {m}");
    let mut means = Vec::new();
    for (window, columns) in m["means"].as_object().unwrap() {
        for (column, v) in columns.as_object().unwrap() {
            if METRICS.contains(&column.as_str()) {
                means.push((window.clone(), column.clone(), v.as_f64().unwrap()));
            }
        }
    }
    (m["jod"].clone(), means)
}

#[test]
fn a_runs_frames_measured_again_give_the_runs_metrics() {
    let tmp = temp("round_trip");
    let dir = tmp.path().to_path_buf();
    let scenario = dir.join("still.ron");
    std::fs::write(
        &scenario,
        r#"Scenario(
    scene: Builtin("cornell_box"),
    resolution: (24, 16),
    frames: 5,
    seed: 3,
    max_depth: 3,
    methods: [PathTracing(spp: 1), Taa()],
    reference: (spp: 8, frames: Every(1)),
)"#,
    )
    .unwrap();
    let run = dir.join("run");
    let opts = RunOptions {
        scenario,
        overrides: Overrides { out: Some(run.clone()), ..Default::default() },
        cache_dir: Some(dir.join("cache")),
        progress: false,
    };
    let summary = play::run(&opts).expect("the run plays");
    let labels: Vec<String> = {
        let mut l: Vec<String> = summary.records.iter().map(|r| r.method.clone()).collect();
        l.dedup();
        l.sort();
        l.dedup();
        l
    };
    assert_eq!(labels.len(), 2, "{labels:?}");
    let tests: Vec<(&str, PathBuf)> =
        labels.iter().map(|l| (l.as_str(), run.join("frames").join(l))).collect();
    let mut o = options(&run.join("reference"), &tests, dir.join("measured"));
    for l in &labels {
        let motion = run.join("frames").join(l).join("motion");
        if motion.exists() {
            o.motion.push((l.clone(), motion));
        }
    }
    assert!(!o.motion.is_empty(), "TAA writes motion vectors: reprojected SMAPE is compared too");
    measure(&o).expect("measure reads the run's frames");
    let (ours, theirs) = (metric_cells(&dir.join("measured")), metric_cells(&run));
    assert_eq!(ours.len(), theirs.len());
    for (a, b) in ours.iter().zip(&theirs) {
        assert_eq!(a, b, "measured vs run");
    }
    assert!(ours.iter().any(|c| c.2 == "flip" && !c.3.is_empty()));
    assert!(ours.iter().any(|c| c.2 == "smape_reprojected" && !c.3.is_empty()));
    for l in &labels {
        let (ours, theirs) = (summary_metrics(&dir.join("measured"), l), summary_metrics(&run, l));
        assert_eq!(ours.0, theirs.0, "{l}: JOD per window, measured vs run");
        assert!(ours.1.iter().any(|m| m.1 == "psnr"), "{l}: {:?}", ours.1);
        assert_eq!(ours.1, theirs.1, "{l}: summary means, measured vs run");
    }
    assert!(dir.join("measured/report.html").exists());
}

/// A tiny sequence of `n` frames of `w`x`h` in `dir` (EXR), value `v` per frame.
fn sequence(dir: &Path, n: u32, wh: (u32, u32), v: impl Fn(u32) -> f32) {
    sequence_from(dir, 0, n, wh, v)
}

/// `sequence` with its frames numbered from `first` in the file names.
fn sequence_from(dir: &Path, first: u32, n: u32, (w, h): (u32, u32), v: impl Fn(u32) -> f32) {
    std::fs::create_dir_all(dir).unwrap();
    for f in first..first + n {
        let img = metrics::Image::filled(w, h, [v(f); 3]);
        metrics::write_exr(&img, dir.join(format!("frame_{f:03}.exr"))).unwrap();
    }
}

#[test]
fn bad_input_names_the_file_and_frame_and_writes_nothing() {
    let tmp = temp("bad");
    let dir = tmp.path().to_path_buf();
    let reference = dir.join("reference");
    sequence(&reference, 4, (8, 8), |_| 0.5);
    sequence(&dir.join("ok"), 4, (8, 8), |f| 0.4 + 0.05 * f as f32);
    sequence(&dir.join("small"), 4, (8, 6), |_| 0.5);
    sequence(&dir.join("short"), 3, (8, 8), |_| 0.5);
    sequence(&dir.join("nan"), 4, (8, 8), |f| if f == 2 { f32::NAN } else { 0.5 });
    let gap = dir.join("gap");
    sequence(&gap, 4, (8, 8), |_| 0.5);
    std::fs::remove_file(gap.join("frame_001.exr")).unwrap();
    let broken = dir.join("broken");
    sequence(&broken, 4, (8, 8), |_| 0.5);
    std::fs::write(broken.join("frame_003.exr"), b"not an exr").unwrap();
    let out = dir.join("out");
    let cases: [(&str, &[&str]); 5] = [
        ("small", &["small/frame_000.exr", "frame 0", "8x6", "8x8"]),
        ("short", &["short", "frame 3 is missing"]),
        ("nan", &["nan/frame_002.exr", "frame 2", "non-finite"]),
        ("gap", &["gap", "frame 1 is missing"]),
        ("broken", &["broken/frame_003.exr", "frame 3"]),
    ];
    for (name, expected) in cases {
        let o = options(&reference, &[("ok", dir.join("ok")), (name, dir.join(name))], out.clone());
        let e = format!("{:#}", measure(&o).unwrap_err());
        for x in expected {
            assert!(e.contains(x), "{name}: `{x}` not in: {e}");
        }
        assert!(!out.exists(), "{name}: something was written");
    }
    let mut o = options(&reference, &[("ok", dir.join("ok"))], out.clone());
    o.cvvdp.display = "crt_1985".into();
    assert!(format!("{:#}", measure(&o).unwrap_err()).contains("unknown display 'crt_1985'"));
    assert!(!out.exists());
    // The good pair alone is measured: an event splits the windows.
    let mut o = options(&reference, &[("ok", dir.join("ok"))], out.clone());
    o.events = vec![2];
    measure(&o).unwrap();
    let s: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(out.join("summary.json")).unwrap()).unwrap();
    let jod = &s["methods"][0]["jod"];
    for w in ["before_first_event", "after_event_0", "overall"] {
        let v = jod[w].as_f64().unwrap_or_else(|| panic!("no JOD for {w}: {s}"));
        assert!((0.0..=10.0).contains(&v), "{w}: {v}");
    }
}

/// `--timings`: an outside method's per-frame times land in frames.csv (wall_ms_total and its
/// passes, the rest of the total as `other`) and put it on the speed-against-accuracy charts;
/// timings of the wrong length or with a bad cell are errors naming the file and frame or line,
/// with nothing written.
#[test]
fn timings_put_an_outside_method_on_the_speed_charts() {
    let tmp = temp("timings");
    let dir = tmp.path().to_path_buf();
    let reference = dir.join("reference");
    sequence(&reference, 4, (8, 8), |_| 0.5);
    sequence(&dir.join("mine"), 4, (8, 8), |f| 0.4 + 0.05 * f as f32);
    let write = |name: &str, text: &str| {
        let p = dir.join(name);
        std::fs::write(&p, text).unwrap();
        p
    };
    let good =
        write("good.csv", "frame,ms,trace,denoise\n0,3.5,2,1\n1,4,2.5,1\n2,5,3,1.5\n3,4.5,3,1\n");
    let out = dir.join("out");
    let cases: [(&str, &str, &[&str]); 5] = [
        ("short.csv", "frame,ms\n0,1\n1,1\n2,1\n", &["short.csv", "frame 3 is missing"]),
        (
            "long.csv",
            "frame,ms\n0,1\n1,1\n2,1\n3,1\n4,1\n",
            &["long.csv:6", "frame 4 has no reference frame"],
        ),
        ("bad.csv", "frame,ms\n0,1\n1,fast\n2,1\n3,1\n", &["bad.csv:3", "frame 1", "fast"]),
        ("header.csv", "frame,time\n0,1\n", &["header.csv:1", "frame,ms"]),
        (
            "over.csv",
            "frame,ms,a\n0,1,2\n1,1,0\n2,1,0\n3,1,0\n",
            &["over.csv:2", "frame 0", "more than"],
        ),
    ];
    for (name, text, expected) in cases {
        let mut o = options(&reference, &[("mine", dir.join("mine"))], out.clone());
        o.timings = vec![("mine".into(), write(name, text))];
        let e = format!("{:#}", measure(&o).unwrap_err());
        for x in expected {
            assert!(e.contains(x), "{name}: `{x}` not in: {e}");
        }
        assert!(!out.exists(), "{name}: something was written");
    }
    let mut o = options(&reference, &[("mine", dir.join("mine"))], out.clone());
    o.timings = vec![("mine".into(), good)];
    measure(&o).unwrap();
    let csv = std::fs::read_to_string(out.join("frames.csv")).unwrap();
    assert_eq!(column(&csv, "wall_ms_total"), [3.5, 4.0, 5.0, 4.5]);
    assert_eq!(column(&csv, "wall_ms_other")[0], 0.5);
    assert_eq!(column(&csv, "wall_ms_trace")[2], 3.0);
    let charts: Vec<String> = std::fs::read_dir(out.join("charts"))
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .collect();
    assert!(charts.iter().any(|c| c.starts_with("speed_vs_flip")), "{charts:?}");
    // Timings are matched by the inputs' own frame numbers, not by position: frames numbered
    // from 7 (frames.csv counts from 0) take the rows of 7, 8, 9 and 10.
    let (reference, mine) = (dir.join("reference_7"), dir.join("mine_7"));
    sequence_from(&reference, 7, 4, (8, 8), |_| 0.5);
    sequence_from(&mine, 7, 4, (8, 8), |f| 0.4 + 0.05 * f as f32);
    let late = write("late.csv", "frame,ms\n8,6\n7,5\n10,8\n9,7\n");
    let out = dir.join("out_7");
    let mut o = options(&reference, &[("mine", mine)], out.clone());
    o.timings = vec![("mine".into(), late)];
    measure(&o).unwrap();
    let csv = std::fs::read_to_string(out.join("frames.csv")).unwrap();
    assert_eq!(column(&csv, "frame"), [0.0, 1.0, 2.0, 3.0], "{csv}");
    assert_eq!(column(&csv, "wall_ms_total"), [5.0, 6.0, 7.0, 8.0], "{csv}");
}

/// frames.csv's column `name`, row by row, as numbers.
fn column(csv: &str, name: &str) -> Vec<f64> {
    let mut lines = csv.lines();
    let header: Vec<&str> = lines.next().unwrap().split(',').collect();
    let i = header.iter().position(|h| *h == name).unwrap_or_else(|| panic!("no {name}: {csv}"));
    lines
        .map(|l| {
            let cell = l.split(',').nth(i).unwrap();
            cell.parse().unwrap_or_else(|e| panic!("{name} `{cell}` in `{l}`: {e}"))
        })
        .collect()
}
