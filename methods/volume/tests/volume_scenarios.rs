//! The VolumeTransmittance method plays the shipped volume scenarios: one row per estimator
//! with its pass time, density lookups per estimate and bias/std stats; the bias and std maps
//! written next to its frames; a scenario without media refuses the method by name.

use std::path::Path;

use playback::play::{RunOptions, run_spec};
use playback::scenario::{Overrides, RunSpec};

fn play(scenario: &str, out: &Path) -> playback::play::RunSummary {
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../scenarios").join(scenario);
    let overrides = Overrides {
        resolution: Some((32, 18)),
        spp: Some(8),
        out: Some(out.to_path_buf()),
        ..Default::default()
    };
    let spec = RunSpec::load(&path, &overrides).unwrap_or_else(|e| panic!("{e:#}"));
    run_spec(
        &spec,
        &RunOptions {
            scenario: path,
            overrides,
            cache_dir: Some(out.join("cache")),
            progress: false,
        },
    )
    .unwrap_or_else(|e| panic!("{e:#}"))
}

fn stat(r: &frame::frame_record::FrameRecord, name: &str) -> f64 {
    r.stats
        .iter()
        .find(|(n, _)| n == name)
        .unwrap_or_else(|| panic!("{} has no {name}: {:?}", r.method, r.stats))
        .1
}

#[test]
fn volume_scenarios_play_every_estimator() {
    for scenario in ["volume_cloud.ron", "volume_explosion.ron"] {
        let tmp = tempfile::tempdir().unwrap();
        let out = tmp.path().join(format!("flicker_volume_{scenario}"));
        let summary = play(scenario, &out);
        assert_eq!(summary.records.len(), 6, "{scenario}: one row per estimator");
        for r in &summary.records {
            assert!(
                r.passes.iter().any(|(p, ms)| p == media::gpu::PASS && ms.is_some()),
                "{}: no media pass time",
                r.method
            );
            let lookups = stat(r, "lookups_per_estimate");
            assert!(lookups > 0.0, "{}: no density lookups counted", r.method);
            assert!(stat(r, "mean_std").is_finite() && stat(r, "mean_abs_bias").is_finite());
            for map in ["bias", "std", "exact"] {
                let dir = summary.folder.join("frames").join(&r.method).join(map);
                assert!(
                    dir.read_dir().is_ok_and(|mut d| d.next().is_some()),
                    "{}: no {map} map in {}",
                    r.method,
                    dir.display()
                );
            }
        }
        // Equal mN: naive (16) and jackknife (2 × 8) take the same number of lookups.
        let by = |label: &str| {
            summary
                .records
                .iter()
                .find(|r| r.method.contains(label))
                .unwrap_or_else(|| panic!("no {label} row"))
        };
        assert_eq!(
            stat(by("naive"), "lookups_per_estimate"),
            stat(by("jackknife"), "lookups_per_estimate")
        );
    }
}

#[test]
fn a_scenario_without_media_refuses_the_method() {
    let text = "Scenario(scene: Builtin(\"cornell_box\"), resolution: (32, 18), frames: 1, methods: [VolumeTransmittance(spp: 1)])";
    let scenario = sim::Scenario::from_ron(text, Path::new("inline.ron")).unwrap();
    let tmp = tempfile::tempdir().unwrap();
    let out = tmp.path().join("flicker_volume_none");
    let spec = RunSpec::from_scenario(
        scenario,
        &Overrides { out: Some(out.clone()), ..Default::default() },
    )
    .unwrap();
    let e = run_spec(
        &spec,
        &RunOptions {
            scenario: "inline.ron".into(),
            overrides: Overrides::default(),
            cache_dir: Some(out.join("cache")),
            progress: false,
        },
    )
    .err()
    .expect("refused");
    assert!(format!("{e:#}").contains("declares no media"), "{e:#}");
}
