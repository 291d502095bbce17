//! The VolumePath method and media references in playback: volume_mis.ron plays one row per
//! weight with FLIP and relative MSE against the volumetric reference; volume_moving_light.ron's
//! animated cloud is rebaked per frame (its references change frame to frame, its frames are
//! measured for flicker); a scenario without media refuses the method by name; a scenario with
//! media refuses methods that would render it without them, and more media than the
//! volumetric path tracer binds. Small overrides
//! (32x18, 2 spp, 16 spp references, 2 frames of the moving light) keep it to seconds on lavapipe.

use std::path::Path;

use playback::play::{RunOptions, RunSummary, run_spec};
use playback::scenario::{Overrides, RunSpec};

fn play(scenario: &str, frames: Option<u32>, out: &Path) -> RunSummary {
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../scenarios").join(scenario);
    let overrides = Overrides {
        resolution: Some((32, 18)),
        spp: Some(2),
        frames,
        out: Some(out.to_path_buf()),
        ..Default::default()
    };
    let mut spec = RunSpec::load(&path, &overrides).unwrap_or_else(|e| panic!("{e:#}"));
    spec.scenario.reference.spp = 16;
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

#[test]
fn volume_mis_plays_every_weight_against_the_volumetric_reference() {
    let tmp = tempfile::tempdir().unwrap();
    let out = tmp.path().join("flicker_volume_mis");
    let summary = play("volume_mis.ron", None, &out);
    assert_eq!(summary.records.len(), 6, "one row per weight and combination");
    assert_eq!(summary.references_rendered, 1);
    for r in &summary.records {
        let flip = r.flip.unwrap_or_else(|| panic!("{}: no FLIP against the reference", r.method));
        assert!(flip.is_finite() && flip > 0.0 && flip < 1.0, "{}: FLIP {flip}", r.method);
        assert!(
            r.passes.iter().any(|(p, ms)| p == media::gpu::VOLUME_PATH_PASS && ms.is_some()),
            "{}: no pass time",
            r.method
        );
        println!("{}: FLIP {flip:.4}, rel MSE {:?}", r.method, r.rel_mse);
    }
}

#[test]
fn the_moving_light_scenario_rebakes_its_cloud_and_measures_flicker() {
    let tmp = tempfile::tempdir().unwrap();
    let out = tmp.path().join("flicker_volume_moving");
    let summary = play("volume_moving_light.ron", Some(2), &out);
    // The lamp moves and the cloud turns and pulses: no frame's reference is another's.
    assert_eq!(summary.references_rendered, 2, "cached {}", summary.references_cached);
    assert_eq!(summary.records.len(), 6);
    for r in summary.records.iter().filter(|r| r.frame > 0) {
        assert!(
            r.smape.is_some_and(|s| s.is_finite()) && r.flip.is_some_and(|f| f.is_finite()),
            "{} frame {}: {:?} {:?}",
            r.method,
            r.frame,
            r.smape,
            r.flip
        );
    }
}

#[test]
fn the_mesh_bound_scenario_plays_two_media_and_rebakes_its_turning_torus() {
    let tmp = tempfile::tempdir().unwrap();
    let out = tmp.path().join("flicker_volume_mesh");
    let summary = play("volume_mesh_bound.ron", Some(2), &out);
    // The torus-bounded cloud turns: each frame has its own reference.
    assert_eq!(summary.references_rendered, 2, "cached {}", summary.references_cached);
    assert_eq!(summary.records.len(), 4);
    for r in &summary.records {
        assert!(
            r.flip.is_some_and(|f| f.is_finite() && f > 0.0 && f < 1.0),
            "{} frame {}: FLIP {:?}",
            r.method,
            r.frame,
            r.flip
        );
    }
}

/// The error of running an inline scenario (refused before any frame).
fn refusal(text: &str, name: &str) -> String {
    let scenario = sim::Scenario::from_ron(text, Path::new("inline.ron")).unwrap();
    let tmp = tempfile::tempdir().unwrap();
    let out = tmp.path().join(format!("flicker_volume_path_{name}"));
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
    format!("{e:#}")
}

#[test]
fn a_scenario_without_media_refuses_volume_path() {
    let e = refusal(
        "Scenario(scene: Builtin(\"cornell_box\"), resolution: (32, 18), frames: 1, methods: [VolumePath(spp: 1)])",
        "none",
    );
    assert!(e.contains("declares no media"), "{e}");
}

#[test]
fn a_scenario_with_media_refuses_what_would_leave_them_out() {
    let fog = "(name: \"fog\", kind: Homogeneous, box_min: (-1, -1, -1), box_max: (1, 1, 1), sigma_t: 1.0, resolution: (8, 8, 8))";
    let e = refusal(
        &format!(
            "Scenario(scene: Builtin(\"cornell_box\"), resolution: (32, 18), frames: 1,\n methods: [VolumePath(spp: 1), PathTracing(spp: 1)], media: [{fog}])"
        ),
        "pt",
    );
    assert!(
        e.contains("inline.ron:2:")
            && e.contains("does not render participating media")
            && e.contains("'fog'"),
        "{e}"
    );
    // Several media render together, up to media::gpu::MAX_MEDIA.
    let many: Vec<String> = (0..=media::gpu::MAX_MEDIA).map(|i| format!("(name: \"haze{i}\", kind: Homogeneous, box_min: (-1, -1, -1), box_max: (1, 1, 1), sigma_t: 0.1, resolution: (8, 8, 8))")).collect();
    let e = refusal(
        &format!(
            "Scenario(scene: Builtin(\"cornell_box\"), resolution: (32, 18), frames: 1, methods: [VolumePath(spp: 1)], media: [{}])",
            many.join(", ")
        ),
        "many",
    );
    assert!(
        e.contains(&format!("medium 'haze{}'", media::gpu::MAX_MEDIA))
            && e.contains("renders at most 8 media"),
        "{e}"
    );
}

/// More media than the volumetric path tracer binds are fine where nothing uses it: a
/// VolumeTransmittance method draws its one medium and no reference is rendered.
#[test]
fn more_media_than_the_path_tracer_binds_play_without_references() {
    let many: Vec<String> = (0..=media::gpu::MAX_MEDIA).map(|i| format!("(name: \"haze{i}\", kind: Homogeneous, box_min: (-1, -1, -1), box_max: (1, 1, 1), sigma_t: 0.1, resolution: (8, 8, 8))")).collect();
    let text = format!(
        "Scenario(scene: Builtin(\"cornell_box\"), resolution: (16, 9), frames: 1, reference: (spp: 0, frames: None), methods: [VolumeTransmittance(estimator: RatioTracking, spp: 1, medium: \"haze3\")], media: [{}])",
        many.join(", ")
    );
    let scenario = sim::Scenario::from_ron(&text, Path::new("inline.ron")).unwrap();
    let tmp = tempfile::tempdir().unwrap();
    let out = tmp.path().join("flicker_volume_path_many_transmittance");
    let spec = RunSpec::from_scenario(
        scenario,
        &Overrides { out: Some(out.clone()), ..Default::default() },
    )
    .unwrap();
    let summary = run_spec(
        &spec,
        &RunOptions {
            scenario: "inline.ron".into(),
            overrides: Overrides::default(),
            cache_dir: Some(out.join("cache")),
            progress: false,
        },
    );
    summary.unwrap_or_else(|e| panic!("{e:#}"));
}

/// Bad jackknife settings of VolumePath (m < 2, N < 1, a non-positive step) and a super-voxel
/// edge of 0 are refused with the scenario's file and line, before anything is written.
#[test]
fn bad_jackknife_settings_and_super_voxel_size_are_refused_where_they_stand() {
    let fog = |extra: &str| {
        format!(
            "(name: \"fog\", kind: Homogeneous, box_min: (-1, -1, -1), box_max: (1, 1, 1), sigma_t: 1.0, resolution: (8, 8, 8){extra})"
        )
    };
    let cases = [
        (
            "VolumePath(spp: 1, shadow: Jackknife, shadow_estimates: 1)",
            fog(""),
            "inline.ron:2:",
            "shadow_estimates 1",
        ),
        (
            "VolumePath(spp: 1, shadow: Jackknife, shadow_samples: 0)",
            fog(""),
            "inline.ron:2:",
            "shadow_samples 0",
        ),
        ("VolumePath(spp: 1, shadow_step: Some(0.0))", fog(""), "inline.ron:2:", "shadow_step 0"),
        ("VolumePath(spp: 1, samples: 0)", fog(""), "inline.ron:2:", "samples 0"),
        ("VolumePath(spp: 1)", fog(", super_voxel: 0"), "inline.ron:3:", "super_voxel 0"),
    ];
    for (i, (method, medium, at, what)) in cases.iter().enumerate() {
        let text = format!(
            "Scenario(scene: Builtin(\"cornell_box\"), resolution: (32, 18), frames: 1,\n methods: [{method}],\n media: [{medium}])"
        );
        let tmp = tempfile::tempdir().unwrap();
        let out = tmp.path().join(format!("flicker_volume_path_bad_{i}"));
        let e = match sim::Scenario::from_ron(&text, Path::new("inline.ron")) {
            Err(e) => e.to_string(),
            Ok(scenario) => {
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
                format!("{e:#}")
            }
        };
        assert!(e.contains(at) && e.contains(what), "{method} {medium}: {e}");
        assert!(!out.exists(), "{method}: {} written", out.display());
    }
}
