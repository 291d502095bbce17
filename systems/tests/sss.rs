//! The Sss method (systems::methods::sss) end to end through playback on the shipped scenarios
//! sss_flash.ron, sss_toggle.ron and sss_boids.ron at 32x18: counts within SPVG's clamp, a cold
//! start at n_min, the fixed variant at its count, the count image written; and its input errors.

use std::path::{Path, PathBuf};

use systems::frame_record::FrameRecord;
use systems::playback::{RunOptions, run_spec};
use systems::scenario::{Overrides, RunSpec};

fn play(scenario: &str, frames: u32, keep: &[&str]) -> (Vec<FrameRecord>, PathBuf) {
    let file = Path::new(env!("CARGO_MANIFEST_DIR")).join("..").join("scenarios").join(scenario);
    let dir = std::env::temp_dir().join(format!("sss-e2e-{}-{scenario}", std::process::id()));
    let overrides = Overrides { frames: Some(frames), resolution: Some((32, 18)), out: Some(dir.join("run")), ..Default::default() };
    let mut spec = RunSpec::load(&file, &overrides).expect("scenario");
    spec.methods.retain(|m| keep.contains(&m.label().as_str()));
    assert_eq!(spec.methods.len(), keep.len(), "{scenario}: methods {keep:?}");
    let opts = RunOptions { scenario: file.clone(), overrides, cache_dir: Some(dir.join("cache")), progress: false };
    let summary = run_spec(&spec, &opts).expect("run");
    (summary.records, dir)
}

fn stat(r: &FrameRecord, name: &str) -> f64 {
    r.stats.iter().find(|(k, _)| k == name).unwrap_or_else(|| panic!("{}: no {name}", r.method)).1
}

#[test]
fn sss_scenarios_play_with_clamped_counts() {
    for scenario in ["sss_flash.ron", "sss_toggle.ron", "sss_boids.ron"] {
        let (records, dir) = play(scenario, 5, &["as", "ocv", "fixed64"]);
        assert_eq!(records.len(), 15, "{scenario}");
        for r in &records {
            let (spp, pixels) = (stat(r, "sss_mean_spp"), stat(r, "sss_pixels"));
            assert!(pixels > 20.0, "{scenario} {} frame {}: {pixels} SSS pixels", r.method, r.frame);
            if r.method == "fixed64" {
                assert_eq!(spp, 64.0);
            } else {
                assert!((8.0..=64.0).contains(&spp), "{scenario} {} frame {}: {spp}", r.method, r.frame);
                // No history on the first frame: every SSS pixel at n_min (eq. 4.11/4.12).
                if r.frame == 0 {
                    assert_eq!(spp, 8.0, "{scenario} {}", r.method);
                }
            }
            assert!(r.passes.iter().any(|(p, _)| p == "sss_scatter"), "{scenario}: {:?}", r.passes);
        }
        assert!(dir.join("run/frames/as/sample_count/0004.png").exists(), "{scenario}");
        std::fs::remove_dir_all(&dir).ok();
    }
}

#[test]
fn sss_without_a_subsurface_material_is_refused() {
    let dir = std::env::temp_dir().join(format!("sss-e2e-{}-plain", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let file = dir.join("plain.ron");
    std::fs::write(&file, "Scenario(scene: Builtin(\"sss_sphere\"), resolution: (16, 9), frames: 1, methods: [Sss(variant: Adaptive)])").unwrap();
    let overrides = Overrides { out: Some(dir.join("run")), ..Default::default() };
    let spec = RunSpec::load(&file, &overrides).expect("scenario");
    let opts = RunOptions { scenario: file.clone(), overrides, cache_dir: Some(dir.join("cache")), progress: false };
    let e = format!("{:#}", run_spec(&spec, &opts).err().expect("no subsurface material"));
    assert!(e.contains("no subsurface material") && e.contains("materials:"), "{e}");
    let bad = "Scenario(scene: Builtin(\"sss_sphere\"), resolution: (16, 9), frames: 1,\n methods: [Sss(variant: Adaptive, kappa: 0.2)])";
    std::fs::write(&file, bad).unwrap();
    let e = RunSpec::load(&file, &Overrides::default()).err().expect("unknown field").to_string();
    assert!(e.contains("plain.ron:2:") && e.contains("kappa"), "{e}");
    std::fs::remove_dir_all(&dir).ok();
}
