//! The Sss method (playback::methods::sss) end to end through playback on the shipped scenarios
//! sss_flash.ron, sss_toggle.ron, sss_boids.ron and sss_moving.ron at 32x18: counts within SPVG's clamp, a cold
//! start at n_min, the fixed variant at its count, the count image written; and its input errors.

use std::path::Path;

use frame::frame_record::FrameRecord;
use playback::play::{RunOptions, run_spec};
use playback::scenario::{Overrides, RunSpec};
use statrs::distribution::{ContinuousCDF, StudentsT};

fn play(scenario: &str, frames: u32, keep: &[&str]) -> (Vec<FrameRecord>, tempfile::TempDir) {
    let file = Path::new(env!("CARGO_MANIFEST_DIR")).join("../..").join("scenarios").join(scenario);
    let tmp = tempfile::tempdir().unwrap();
    let dir = tmp.path().to_path_buf();
    let overrides = Overrides {
        frames: Some(frames),
        resolution: Some((32, 18)),
        out: Some(dir.join("run")),
        ..Default::default()
    };
    let mut spec = RunSpec::load(&file, &overrides).expect("scenario");
    spec.methods.retain(|m| keep.contains(&m.label().as_str()));
    assert_eq!(spec.methods.len(), keep.len(), "{scenario}: methods {keep:?}");
    let opts = RunOptions {
        scenario: file.clone(),
        overrides,
        cache_dir: Some(dir.join("cache")),
        progress: false,
    };
    let summary = run_spec(&spec, &opts).expect("run");
    (summary.records, tmp)
}

fn stat(r: &FrameRecord, name: &str) -> f64 {
    r.stats.iter().find(|(k, _)| k == name).unwrap_or_else(|| panic!("{}: no {name}", r.method)).1
}

#[test]
fn sss_scenarios_play_with_clamped_counts() {
    for scenario in ["sss_flash.ron", "sss_toggle.ron", "sss_boids.ron", "sss_moving.ron"] {
        let (records, tmp) = play(scenario, 5, &["as", "ocv", "fixed64"]);
        let dir = tmp.path().to_path_buf();
        assert_eq!(records.len(), 15, "{scenario}");
        for r in &records {
            let (spp, pixels) = (stat(r, "sss_mean_spp"), stat(r, "sss_pixels"));
            assert!(
                pixels > 20.0,
                "{scenario} {} frame {}: {pixels} SSS pixels",
                r.method,
                r.frame
            );
            if r.method == "fixed64" {
                assert_eq!(spp, 64.0);
            } else {
                assert!(
                    (8.0..=64.0).contains(&spp),
                    "{scenario} {} frame {}: {spp}",
                    r.method,
                    r.frame
                );
                // No history on the first frame: every SSS pixel at n_min (eq. 4.11/4.12).
                if r.frame == 0 {
                    assert_eq!(spp, 8.0, "{scenario} {}", r.method);
                }
            }
            assert!(r.passes.iter().any(|(p, _)| p == "sss_scatter"), "{scenario}: {:?}", r.passes);
        }
        assert!(dir.join("run/frames/as/sample_count/0004.png").exists(), "{scenario}");
    }
}

#[test]
fn sss_without_a_subsurface_material_is_refused() {
    let tmp = tempfile::tempdir().unwrap();
    let dir = tmp.path().to_path_buf();
    std::fs::create_dir_all(&dir).unwrap();
    let file = dir.join("plain.ron");
    std::fs::write(&file, "Scenario(scene: Builtin(\"sss_sphere\"), resolution: (16, 9), frames: 1, methods: [Sss(variant: Adaptive)])").unwrap();
    let overrides = Overrides { out: Some(dir.join("run")), ..Default::default() };
    let spec = RunSpec::load(&file, &overrides).expect("scenario");
    let opts = RunOptions {
        scenario: file.clone(),
        overrides,
        cache_dir: Some(dir.join("cache")),
        progress: false,
    };
    let e = format!("{:#}", run_spec(&spec, &opts).err().expect("no subsurface material"));
    assert!(e.contains("no subsurface material") && e.contains("materials:"), "{e}");
    let bad = "Scenario(scene: Builtin(\"sss_sphere\"), resolution: (16, 9), frames: 1,\n methods: [Sss(variant: Adaptive, kappa: 0.2)])";
    std::fs::write(&file, bad).unwrap();
    let e = RunSpec::load(&file, &Overrides::default()).expect_err("unknown field").to_string();
    assert!(e.contains("plain.ron:2:") && e.contains("kappa"), "{e}");
    let separable_afis = "Scenario(scene: Builtin(\"sss_sphere\"), resolution: (16, 9), frames: 1,\n methods: [Sss(variant: Separable(taps: 5), prefilter: ())],\n materials: [(material: \"skin\", subsurface: (dmfp: (0.1, 0.05, 0.02)))])";
    std::fs::write(&file, separable_afis).unwrap();
    let overrides = Overrides { out: Some(dir.join("run_afis")), ..Default::default() };
    let spec = RunSpec::load(&file, &overrides).expect("scenario");
    let opts = RunOptions {
        scenario: file.clone(),
        overrides,
        cache_dir: Some(dir.join("cache")),
        progress: false,
    };
    let e = format!("{:#}", run_spec(&spec, &opts).err().expect("separable with prefilter"));
    assert!(e.contains("prefilter with Separable"), "{e}");
}

/// γ or ε_u outside [0, 1]: an error at the method's file:line naming the setting, and no run
/// folder written.
#[test]
fn split_settings_outside_the_unit_interval_are_refused_at_file_line() {
    let tmp = tempfile::tempdir().unwrap();
    let dir = tmp.path().to_path_buf();
    std::fs::create_dir_all(&dir).unwrap();
    let file = dir.join("split.ron");
    for (bad, what) in [("(eps_u: 1.5)", "eps_u"), ("(gamma: Some(-0.2))", "gamma")] {
        let text = format!(
            "Scenario(scene: Builtin(\"sss_sphere\"), resolution: (16, 9), frames: 1,\n methods: [Sss(variant: Adaptive, split: {bad})],\n materials: [{SKIN}])"
        );
        std::fs::write(&file, text).unwrap();
        let out = dir.join("run");
        let overrides = Overrides { out: Some(out.clone()), ..Default::default() };
        let spec = RunSpec::load(&file, &overrides).expect("scenario");
        let opts = RunOptions {
            scenario: file.clone(),
            overrides,
            cache_dir: Some(dir.join("cache")),
            progress: false,
        };
        let e = format!("{:#}", run_spec(&spec, &opts).err().expect("bad split"));
        assert!(e.contains("split.ron:2:") && e.contains(what) && e.contains("[0, 1]"), "{e}");
        assert!(!out.exists(), "{bad}: the run folder was written");
    }
}

const SKIN: &str = "(material: \"skin\", subsurface: (dmfp: (0.12, 0.05, 0.025)))";

/// Plays an inline scenario on the skin sphere (constant lamp, no animation) at 32x18.
fn play_inline(
    name: &str,
    seed: u64,
    frames: u32,
    methods: &str,
) -> (Vec<FrameRecord>, tempfile::TempDir) {
    play_with_materials(name, seed, frames, methods, &[SKIN])
}

fn play_with_materials(
    name: &str,
    seed: u64,
    frames: u32,
    methods: &str,
    materials: &[&str],
) -> (Vec<FrameRecord>, tempfile::TempDir) {
    let tmp = tempfile::tempdir().unwrap();
    let dir = tmp.path().to_path_buf();
    std::fs::create_dir_all(&dir).unwrap();
    let file = dir.join(format!("{name}.ron"));
    let text = format!(
        "Scenario(scene: Builtin(\"sss_sphere\"), resolution: (32, 18), frames: {frames}, seed: {seed}, max_depth: 2,\n methods: [{methods}],\n materials: [{}])",
        materials.join(", ")
    );
    std::fs::write(&file, text).unwrap();
    let overrides = Overrides { out: Some(dir.join("run")), ..Default::default() };
    let spec = RunSpec::load(&file, &overrides).expect("scenario");
    let opts = RunOptions {
        scenario: file.clone(),
        overrides,
        cache_dir: Some(dir.join("cache")),
        progress: false,
    };
    (run_spec(&spec, &opts).expect("run").records, tmp)
}

/// TAA after the pass (taa's resolve, Sec. 4.3): the first frame has no history and is
/// the pass's own image; later frames blend the history, so in a still scene the frame-to-frame
/// flicker (SMAPE) falls below the pass without TAA: a one-sided 95% Student-t bound over 3
/// seeds. The separable baseline runs beside them: 2 x 25 fetches per SSS pixel, its two passes
/// timed.
#[test]
fn taa_after_the_pass_lowers_flicker_and_separable_runs() {
    const FRAMES: u32 = 8;
    let mut gaps = vec![];
    for seed in 1..=3u64 {
        let methods = "Sss(variant: Adaptive, name: \"as\"), Sss(variant: Adaptive, taa: (alpha: 0.1), name: \"as_taa\"), Sss(variant: Separable(taps: 25), name: \"separable\"), Sss(variant: Adaptive, prefilter: ())";
        let (records, tmp) = play_inline("taa", seed, FRAMES, methods);
        let dir = tmp.path().to_path_buf();
        let image = |m: &str, f: u32| {
            frame::output::read_exr(&dir.join(format!("run/frames/{m}/{f:04}.exr"))).unwrap().2
        };
        assert_eq!(image("as", 0), image("as_taa", 0), "seed {seed}: frame 0 has no history");
        assert_ne!(image("as", 3), image("as_taa", 3), "seed {seed}: TAA changed nothing");
        // AFIS (the default label `sss_as_afis`): its own prefiltering pass, a different image.
        assert_ne!(
            image("as", 0),
            image("sss_as_afis", 0),
            "seed {seed}: prefiltering changed nothing"
        );
        for r in records.iter().filter(|r| r.method == "sss_as_afis") {
            assert!(r.passes.iter().any(|(p, _)| p == "sss_prefilter"), "{:?}", r.passes);
        }
        let mean_smape = |m: &str| {
            let v: Vec<f64> = records
                .iter()
                .filter(|r| r.method == m && r.frame > 0)
                .map(|r| r.smape.expect("smape"))
                .collect();
            v.iter().sum::<f64>() / v.len() as f64
        };
        gaps.push(mean_smape("as") - mean_smape("as_taa"));
        for r in records.iter().filter(|r| r.method == "as_taa") {
            assert!(r.passes.iter().any(|(p, _)| p == "taa_resolve"), "{:?}", r.passes);
        }
        for r in records.iter().filter(|r| r.method == "separable") {
            assert_eq!(stat(r, "sss_mean_spp"), 50.0);
            for pass in ["sss_separable_h", "sss_separable_v"] {
                assert!(r.passes.iter().any(|(p, _)| p == pass), "{:?}", r.passes);
            }
        }
    }
    let n = gaps.len() as f64;
    let mean = gaps.iter().sum::<f64>() / n;
    let sd = (gaps.iter().map(|g| (g - mean).powi(2)).sum::<f64>() / (n - 1.0)).sqrt();
    let t95 = StudentsT::new(0.0, 1.0, n - 1.0).unwrap().inverse_cdf(0.95);
    let bound = mean - t95 * sd / n.sqrt();
    eprintln!("SMAPE(as) − SMAPE(as_taa) per seed: {gaps:?}, lower 95% bound {bound}");
    assert!(bound > 0.0, "TAA did not lower flicker: per-seed gaps {gaps:?}, bound {bound}");
}

/// Two subsurface materials: each is scattered by its own profile and reads only its own
/// pixels. Making the floor subsurface too leaves every skin pixel bit-identical to the run
/// where only the skin is, scatters the floor's pixels (they change), and counts both.
#[test]
fn two_subsurface_materials_scatter_apart() {
    let methods = "Sss(variant: Adaptive, name: \"as\")";
    let floor = "(material: \"floor\", subsurface: (dmfp: (0.3, 0.2, 0.1)))";
    let (one, tmp_one) = play_with_materials("one_material", 4, 3, methods, &[SKIN]);
    let (two, tmp_two) = play_with_materials("two_materials", 4, 3, methods, &[SKIN, floor]);
    let (dir_one, dir_two) = (tmp_one.path().to_path_buf(), tmp_two.path().to_path_buf());
    let last = |dir: &Path| frame::output::read_exr(&dir.join("run/frames/as/0002.exr")).unwrap().2;
    let counts = |dir: &Path| {
        metrics::load_image(dir.join("run/frames/as/sample_count/0002.png")).unwrap().rgb
    };
    let (image_one, image_two) = (last(&dir_one), last(&dir_two));
    let (counts_one, counts_two) = (counts(&dir_one), counts(&dir_two));
    let (mut skin, mut floor_changed, mut floor) = (0, 0, 0);
    for i in 0..image_one.len() {
        if counts_one[i][0] > 0.0 {
            skin += 1;
            assert_eq!(
                image_one[i], image_two[i],
                "skin pixel {i} changed when the floor became subsurface"
            );
        } else if counts_two[i][0] > 0.0 {
            floor += 1;
            floor_changed += (image_one[i] != image_two[i]) as usize;
        }
    }
    let pixels = |records: &[FrameRecord]| stat(records.last().unwrap(), "sss_pixels") as usize;
    assert_eq!(pixels(&one), skin);
    assert_eq!(pixels(&two), skin + floor);
    assert!(skin > 20 && floor > 100, "skin {skin}, floor {floor} pixels");
    assert!(floor_changed > floor / 2, "{floor_changed} of {floor} floor pixels scattered");
}

/// The hybrid pass (Sec. 5.3.2) end to end: with the default rule every hybrid pass is timed;
/// a gap no tap reaches gives the separable passes everywhere (2 x 25 fetches per SSS pixel),
/// a gap every tap exceeds gives AFIS everywhere (SPVG's counts, n_min on frame 0, the same
/// image as AFIS alone); without a prefilter it is refused.
#[test]
fn hybrid_runs_both_techniques_end_to_end() {
    let methods = "Sss(variant: Adaptive, prefilter: (), hybrid: (), name: \"hybrid\"), Sss(variant: Adaptive, prefilter: (), hybrid: (max_gap_px: 1e9), name: \"all_separable\"), Sss(variant: Adaptive, prefilter: (), hybrid: (max_gap_px: 1e-9), name: \"all_afis\"), Sss(variant: Adaptive, prefilter: (), name: \"afis\")";
    let (records, tmp) = play_inline("hybrid", 2, 3, methods);
    let dir = tmp.path().to_path_buf();
    let image = |m: &str, f: u32| {
        frame::output::read_exr(&dir.join(format!("run/frames/{m}/{f:04}.exr"))).unwrap().2
    };
    for r in &records {
        let spp = stat(r, "sss_mean_spp");
        match r.method.as_str() {
            "hybrid" => {
                for pass in [
                    "sss_hybrid_setup",
                    "sss_prefilter",
                    "sss_scatter",
                    "sss_separable_h",
                    "sss_separable_v",
                    "sss_hybrid_copy",
                ] {
                    assert!(r.passes.iter().any(|(p, _)| p == pass), "{pass}: {:?}", r.passes);
                }
            }
            "all_separable" => assert_eq!(spp, 50.0, "frame {}", r.frame),
            "all_afis" => {
                assert!((8.0..=64.0).contains(&spp), "frame {}: {spp}", r.frame);
                if r.frame == 0 {
                    assert_eq!(spp, 8.0);
                }
                assert_eq!(image("all_afis", r.frame), image("afis", r.frame), "frame {}", r.frame);
            }
            _ => {}
        }
    }
    drop(tmp);
    let tmp = tempfile::tempdir().unwrap();
    let (dir, file) = {
        let dir = tmp.path().to_path_buf();
        std::fs::create_dir_all(&dir).unwrap();
        let file = dir.join("hybrid.ron");
        (dir, file)
    };
    let text = format!(
        "Scenario(scene: Builtin(\"sss_sphere\"), resolution: (16, 9), frames: 1,\n methods: [Sss(variant: Adaptive, hybrid: ())],\n materials: [{SKIN}])"
    );
    std::fs::write(&file, text).unwrap();
    let out = dir.join("run");
    let overrides = Overrides { out: Some(out.clone()), ..Default::default() };
    let spec = RunSpec::load(&file, &overrides).expect("scenario");
    let opts = RunOptions {
        scenario: file.clone(),
        overrides,
        cache_dir: Some(dir.join("cache")),
        progress: false,
    };
    let e = format!("{:#}", run_spec(&spec, &opts).err().expect("hybrid without prefilter"));
    assert!(e.contains("hybrid without prefilter"), "{e}");
    assert!(!out.exists(), "the run folder was written");
}

/// scenarios/sss_hybrid.ron at its own 96x54 (the profile's size in pixels decides): the hybrid
/// takes both paths in one frame, each pixel's value that of AFIS alone (the near floor's tiles)
/// or of the separable passes alone (the skin's, the far floor's), each on many pixels.
#[test]
fn the_hybrid_scenario_takes_both_paths() {
    let file = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../scenarios/sss_hybrid.ron");
    let tmp = tempfile::tempdir().unwrap();
    let dir = tmp.path().to_path_buf();
    let overrides = Overrides { frames: Some(1), out: Some(dir.join("run")), ..Default::default() };
    let mut spec = RunSpec::load(&file, &overrides).expect("scenario");
    spec.methods.retain(|m| m.label() != "pass_2048");
    let opts = RunOptions {
        scenario: file.clone(),
        overrides,
        cache_dir: Some(dir.join("cache")),
        progress: false,
    };
    run_spec(&spec, &opts).expect("run");
    let image =
        |m: &str| frame::output::read_exr(&dir.join(format!("run/frames/{m}/0000.exr"))).unwrap().2;
    let (hybrid, afis, separable) = (image("hybrid"), image("afis"), image("separable"));
    let (mut as_afis, mut as_separable) = (0, 0);
    for ((h, a), s) in hybrid.iter().zip(&afis).zip(&separable) {
        if a == s {
            continue;
        }
        as_afis += (h == a) as usize;
        as_separable += (h == s) as usize;
    }
    eprintln!("{as_afis} pixels as AFIS alone, {as_separable} as separable alone");
    assert!(as_afis > 500 && as_separable > 500, "{as_afis} AFIS, {as_separable} separable pixels");
}

/// The thesis's irradiance (`irradiance: Direct`, the default) has no Monte Carlo noise: on the
/// still skin sphere the mean irradiance the pass scatters (`sss_irradiance`) is the same number
/// on every seed and frame, while the path-traced one (1 spp) differs between seeds. SPVG then
/// sees only the lighting's change, as under the thesis's deferred lighting.
#[test]
fn the_direct_irradiance_is_the_same_on_every_seed_of_a_still_frame() {
    let methods = "Sss(variant: Adaptive, name: \"direct\"), Sss(variant: Adaptive, irradiance: PathTraced, name: \"traced\")";
    let mut direct = vec![];
    let mut traced = vec![];
    for seed in 1..=3u64 {
        let (records, _tmp) = play_inline("direct_seeds", seed, 2, methods);
        for r in &records {
            let e = stat(r, "sss_irradiance");
            assert!(e > 0.0, "seed {seed} {} frame {}: irradiance {e}", r.method, r.frame);
            match r.method.as_str() {
                "direct" => {
                    direct.push(e);
                    assert!(r.passes.iter().any(|(p, _)| p == "sss_direct"), "{:?}", r.passes);
                }
                _ => traced.push(e),
            }
        }
    }
    assert_eq!(direct.len(), 6);
    assert!(direct.iter().all(|&e| e == direct[0]), "direct irradiance varies: {direct:?}");
    let spread = traced.iter().fold(f64::NEG_INFINITY, |a, &b| a.max(b))
        - traced.iter().fold(f64::INFINITY, |a, &b| a.min(b));
    assert!(spread > 0.0, "the path-traced irradiance did not vary: {traced:?}");
    eprintln!("direct {:.6}, path traced {traced:?}", direct[0]);
}

/// `distant_count: GammaScaled` reaches the pass through a scenario: with SPVG's count pinned
/// (n_min = n_max = 16) and a constant γ, every frame's mean count per SSS pixel is eq. 5.20's
/// round(16·γ) (4 at γ = 0.25, 8 at 0.5, 12 at 0.75), and Algorithm 3's 16 without the setting.
#[test]
fn gamma_scaled_counts_follow_eq_5_20_through_a_run() {
    let method = |gamma: f64, rule: &str, name: &str| {
        format!(
            "Sss(variant: Adaptive, spvg: (n_min: 16, n_max: 16), split: (gamma: Some({gamma}), eps_u: 0.01), distant_count: {rule}, name: \"{name}\")"
        )
    };
    let methods = [
        method(0.25, "GammaScaled", "quarter"),
        method(0.5, "GammaScaled", "half"),
        method(0.75, "GammaScaled", "three_quarters"),
        method(0.25, "Estimated", "algorithm3"),
    ]
    .join(", ");
    let (records, _tmp) = play_inline("eq520", 5, 3, &methods);
    assert_eq!(records.len(), 12);
    for r in &records {
        let expected = match r.method.as_str() {
            "quarter" => 4.0,
            "half" => 8.0,
            "three_quarters" => 12.0,
            _ => 16.0,
        };
        assert!(stat(r, "sss_pixels") > 20.0, "{} frame {}", r.method, r.frame);
        assert_eq!(stat(r, "sss_mean_spp"), expected, "{} frame {}", r.method, r.frame);
    }
}
