//! Rules that read the same cache share one: in one run, the termination methods whose settings
//! have one cache key (all but the rule, survival and radiance unit; path tracing apart) run the
//! cache's passes once a frame, and each method's images and metrics are bit for bit those it
//! gives alone (methods/termination/README.md, "One frame").

use std::path::Path;

use frame::frame_record::FrameRecord;
use frame::run_folder::RunFolder;
use playback::play::{RunOptions, run_spec};
use playback::scenario::{Overrides, RunSpec};

const FRAMES: u32 = 2;
/// (name, settings) of the methods: three rules on one cache (one with roulette, one in another
/// radiance unit), path tracing (its own cache), and a rule with another capacity (its own).
const METHODS: [(&str, &str); 5] = [
    (
        "vb_rel",
        "rule: VarianceBounding(t: 1.0, relative: true), capacity: 4096, samples_per_vertex: 4",
    ),
    (
        "vb_q60",
        "rule: VarianceBounding(t: 0.01), survival: 0.6, radiance_scale: Stated, radiance_unit: 0.017, capacity: 4096, samples_per_vertex: 4",
    ),
    ("spread", "rule: AreaSpread(c: 0.01), capacity: 4096, samples_per_vertex: 4"),
    ("pt", "rule: PathTracing, capacity: 4096, samples_per_vertex: 4"),
    ("first_small", "rule: FirstVertex, capacity: 2048, samples_per_vertex: 4"),
];
/// The cache of each method of [`METHODS`] (index of its owner, the first method with it).
const OWNER: [usize; 5] = [0, 0, 0, 3, 4];
const SHARED_PASSES: [&str; 4] = ["tc_propagate", "tc_fold", "tc_insert", "tc_store"];

struct Run {
    records: Vec<FrameRecord>,
    folder: RunFolder,
    /// The run's folder and its reference cache, removed when the run is dropped.
    _root: tempfile::TempDir,
}

fn play(methods: &[(&str, &str)], name: &str) -> Run {
    let methods: Vec<String> = methods
        .iter()
        .map(|(label, settings)| {
            format!(
                "Termination({settings}, store_probability: 0.2, warmup_frames: 3, name: \"{label}\")"
            )
        })
        .collect();
    let text = format!(
        "Scenario(scene: Builtin(\"door_gap\"), resolution: (16, 9), frames: {FRAMES}, seed: 3, max_depth: 8,\n methods: [{}],\n reference: (spp: 0, frames: None))",
        methods.join(",\n ")
    );
    let root =
        tempfile::Builder::new().prefix(&format!("termination-shared-{name}-")).tempdir().unwrap();
    let dir = root.path().join("run");
    let scenario = sim::Scenario::from_ron(&text, Path::new("inline.ron")).expect("scenario");
    let overrides = Overrides { out: Some(dir.clone()), ..Default::default() };
    let spec = RunSpec::from_scenario(scenario, &overrides).expect("spec");
    let opts = RunOptions {
        scenario: "inline.ron".into(),
        overrides: Overrides::default(),
        cache_dir: Some(dir.with_file_name("cache")),
        progress: false,
    };
    let summary = run_spec(&spec, &opts).expect("run");
    Run { records: summary.records, folder: RunFolder::new(&summary.folder), _root: root }
}

fn record<'a>(run: &'a Run, method: &str, frame: u32) -> &'a FrameRecord {
    run.records
        .iter()
        .find(|r| r.method == method && r.frame == frame)
        .unwrap_or_else(|| panic!("no frame {frame} of {method}"))
}

/// The record's metrics: everything but its times.
fn metrics(r: &FrameRecord) -> String {
    format!("{:?} {:?} {:?} {:?} {:?}", r.rays, r.shaded, r.mse, r.flip, r.stats)
}

#[test]
fn rules_on_one_cache_give_their_own_results_with_one_propagation() {
    let together = play(&METHODS, "together");
    for (i, &method) in METHODS.iter().enumerate() {
        let alone = play(&[method], &format!("alone{i}"));
        let name = method.0;
        for f in 0..FRAMES {
            for (what, image) in [("image", None), ("path length", Some("path_length"))] {
                let path = |d: &RunFolder| match image {
                    None => d.frame(name, f, "exr"),
                    Some(image) => d.method_image(name, image, f, "exr"),
                };
                let a = std::fs::read(path(&alone.folder)).expect("alone's image");
                let b = std::fs::read(path(&together.folder)).expect("shared image");
                assert!(a == b, "{name} frame {f}: the {what} differs from the method's alone");
            }
            assert_eq!(
                metrics(record(&alone, name, f)),
                metrics(record(&together, name, f)),
                "{name} frame {f}: metrics"
            );
            // Alone, every method pays the cache's passes.
            let passes = |r: &FrameRecord| r.passes.iter().map(|(p, _)| p.clone()).collect();
            let alone_passes: Vec<String> = passes(record(&alone, name, f));
            for p in SHARED_PASSES.iter().chain(&["tc_trace"]) {
                assert_eq!(alone_passes.iter().filter(|x| x == p).count(), 1, "{name} alone: {p}");
            }
        }
    }
    // Together, the cache's passes run once a frame per cache, reported by its owner; every
    // method reports its own trace.
    for f in 0..FRAMES {
        for (i, (name, _)) in METHODS.iter().enumerate() {
            let r = record(&together, name, f);
            let count = |p: &str| r.passes.iter().filter(|(x, _)| x == p).count();
            assert_eq!(count("tc_trace"), 1, "{}: own trace", r.method);
            for p in SHARED_PASSES {
                let expected = usize::from(OWNER[i] == i);
                assert_eq!(count(p), expected, "{} frame {f}: {p} (owner {})", r.method, OWNER[i]);
            }
        }
    }
}
