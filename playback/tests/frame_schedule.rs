//! The frame's schedule: stages in order, each method's systems in their stage, misplaced
//! systems detected; scenario methods parsed by their own settings, labels unique.

use std::path::Path;

use bevy_ecs::prelude::*;
use frame::{self, Stage};
use playback::methods::Method;
use playback::scenario::{Overrides, RunSpec};

fn spec(methods: &str) -> RunSpec {
    let text = format!(
        "Scenario(scene: Builtin(\"cornell_box\"), resolution: (32, 18), frames: 2,\n  methods: [{methods}])"
    );
    let scenario =
        sim::Scenario::from_ron(&text, Path::new("inline.ron")).unwrap_or_else(|e| panic!("{e}"));
    RunSpec::from_scenario(scenario, &Overrides::default()).unwrap_or_else(|e| panic!("{e:#}"))
}

fn listing(methods: &[Method]) -> Vec<(Stage, String)> {
    let mut schedule = playback::methods::schedule_for(methods);
    frame::listing(&mut schedule, &mut World::new()).unwrap_or_else(|e| panic!("{e}"))
}

/// The systems of `stage` in execution order.
fn in_stage(listing: &[(Stage, String)], stage: Stage) -> Vec<String> {
    listing.iter().filter(|(s, _)| *s == stage).map(|(_, n)| n.clone()).collect()
}

fn position(listing: &[(Stage, String)], name: &str) -> usize {
    listing
        .iter()
        .position(|(_, n)| n == name)
        .unwrap_or_else(|| panic!("{name} is not in the frame: {listing:?}"))
}

#[test]
fn every_method_system_runs_in_its_stage_in_order() {
    let s = spec(
        "PathTracing(spp: 1), Nirc(spp: 1, predictor: Blend), SampleCache(), Taa(), HashCache(taa: true)",
    );
    let l = listing(&s.methods);
    // Stages never interleave: listing() refuses an out-of-order system, so this is the order.
    let stages: Vec<Stage> = l.iter().map(|(s, _)| *s).collect();
    let mut sorted = stages.clone();
    sorted.sort();
    assert_eq!(stages, sorted);
    assert!(Stage::ALL.iter().all(|s| stages.contains(s)), "a stage without systems: {l:?}");

    let simulate = in_stage(&l, Stage::Simulate);
    assert_eq!(simulate.first().map(String::as_str), Some("simulation::advance_clock"));
    for name in [
        "rotate::rotate",
        "flash::flash",
        "boids::flock",
        "events::apply_events",
        "transform::propagate_transforms",
    ] {
        assert!(simulate.contains(&name.to_string()), "{name} not in Simulate: {simulate:?}");
    }
    assert_eq!(
        in_stage(&l, Stage::Extract),
        [
            "simulation::extract_scene",
            "extract::frame_number",
            "extract::upload_scene",
            "scene_medium::upload_medium"
        ]
    );

    let render = in_stage(&l, Stage::Render);
    for name in [
        "reference::render_reference",
        "path_tracing::render",
        "nirc::camera_paths",
        "nirc::infer",
        "sample_cache::reproject",
        "sample_cache::retrace",
        "sample_cache::shade",
        "sample_cache::reconstruct",
        "taa::trace",
        "taa::resolve",
        "hash_cache::update",
        "hash_cache::resolve",
    ] {
        assert!(render.contains(&name.to_string()), "{name} not in Render: {render:?}");
    }
    assert_eq!(
        in_stage(&l, Stage::Learn),
        [
            "nirc::reliability",
            "nirc::train",
            "nirc::ema",
            "nirc::reliability_update",
            "nirc::frame_output"
        ]
    );
    assert_eq!(
        in_stage(&l, Stage::Measure),
        [
            "measure::prepare",
            "measure::smape_vs_previous",
            "measure::flip_vs_reference",
            "measure::regions"
        ]
    );
    assert_eq!(
        in_stage(&l, Stage::Record),
        [
            "record::write_reference",
            "record::write_method_images",
            "record::write_frames_csv",
            "record::end_frame"
        ]
    );

    // Within a method, its passes run in the paper's order.
    for pair in [
        ("sample_cache::reproject", "sample_cache::retrace"),
        ("sample_cache::retrace", "sample_cache::shade"),
        ("sample_cache::shade", "sample_cache::reconstruct"),
        ("taa::trace", "taa::resolve"),
        ("hash_cache::update", "hash_cache::resolve"),
        ("nirc::camera_paths", "nirc::infer"),
        ("nirc::infer", "nirc::train"),
        ("nirc::train", "nirc::ema"),
        ("nirc::ema", "nirc::reliability_update"),
    ] {
        assert!(
            position(&l, pair.0) < position(&l, pair.1),
            "{} should run before {}",
            pair.0,
            pair.1
        );
    }
}

/// The caches' upkeep is named systems: what the image reads in Render before it, what the next
/// frame reads in Learn after it.
#[test]
fn cache_upkeep_runs_in_its_stage() {
    let before_in_render = |l: &[(Stage, String)], first: &str, then: &str| {
        let render = in_stage(l, Stage::Render);
        let at = |n: &str| render.iter().position(|r| r == n);
        assert!(
            at(first).is_some() && at(first) < at(then),
            "{first}, {then} in Render: {render:?}"
        );
    };
    let l = listing(&spec("Termination(rule: VarianceBounding(t: 0.1))").methods);
    before_in_render(&l, "termination::update", "termination::trace");
    assert_eq!(in_stage(&l, Stage::Learn), ["termination::store"]);

    // The hash cache's update feeds its image, so all of it runs in Render, before the resolve.
    let l = listing(&spec("HashCache(taa: true)").methods);
    before_in_render(&l, "hash_cache::update", "hash_cache::resolve");
    assert_eq!(in_stage(&l, Stage::Learn), Vec::<String>::new());

    // `flicker schedule` lists them under their stages.
    let text = playback::methods::describe_schedule(
        &spec("HashCache(), Termination(rule: FirstVertex)").methods,
    )
    .unwrap();
    let at = |s: &str| text.find(s).unwrap_or_else(|| panic!("{s} missing from:\n{text}"));
    let (render, learn, measure) = (at("\nRender\n"), at("\nLearn\n"), at("\nMeasure\n"));
    assert!(learn < at("termination::store") && at("termination::store") < measure, "{text}");
    for name in ["hash_cache::update", "termination::update", "termination::trace"] {
        assert!(render < at(name) && at(name) < learn, "{text}");
    }
}

#[test]
fn a_scene_pays_only_for_its_methods() {
    let l = listing(&spec("PathTracing(spp: 1)").methods);
    assert!(
        l.iter().all(|(_, n)| !n.starts_with("nirc::")
            && !n.starts_with("taa::")
            && !n.starts_with("sample_cache::")),
        "{l:?}"
    );
    assert_eq!(in_stage(&l, Stage::Learn), Vec::<String>::new());
    assert!(l.iter().any(|(_, n)| n == "path_tracing::render"));
}

fn stray() {}
fn early() {}

#[test]
fn misplaced_systems_are_detected() {
    // A system outside every stage.
    let mut schedule = frame::new_schedule();
    frame::add_core_systems(&mut schedule);
    schedule.add_systems(stray);
    let e = frame::listing(&mut schedule, &mut World::new()).unwrap_err();
    assert!(e.contains("stray") && e.contains("no stage"), "{e}");

    // A Learn system that would have to run before Simulate: the stages' order makes it a cycle.
    let mut schedule = frame::new_schedule();
    frame::add_core_systems(&mut schedule);
    schedule.add_systems(early.in_set(Stage::Learn).before(sim::advance_clock));
    assert!(frame::listing(&mut schedule, &mut World::new()).is_err());
}

#[test]
fn describe_groups_systems_by_stage() {
    let text =
        playback::methods::describe_schedule(&spec("Taa(), PathTracing(spp: 2)").methods).unwrap();
    let at = |s: &str| text.find(s).unwrap_or_else(|| panic!("{s} missing from:\n{text}"));
    assert!(at("  taa (Taa)") < at("  pt_2spp (PathTracing)"));
    let stages: Vec<usize> = Stage::ALL.iter().map(|s| at(&format!("\n{}\n", s.name()))).collect();
    assert!(stages.windows(2).all(|w| w[0] < w[1]), "{text}");
    assert!(at("taa::trace") > stages[2] && at("taa::resolve") < stages[3]);
}

#[test]
fn methods_take_their_settings_defaults_and_names() {
    let s = spec(
        "Taa(), Taa(name: \"taa_fast\", alpha: 0.2, clamp: MinMax), HashCache(), HashCache(lookup: SecondaryHit, taa: true, capacity: 1024), SampleCache(retrace: Multi)",
    );
    let d = taa::TaaSettings::default();
    assert_eq!(s.methods[0].spec.get::<taa::TaaSettings>(), Some(&d));
    let t = s.methods[1].spec.get::<taa::TaaSettings>().expect("Taa settings");
    assert_eq!((t.alpha, t.clamp, t.jitter_length), (0.2, taa::TaaClamp::MinMax, d.jitter_length));
    let labels: Vec<String> = s.methods.iter().map(|m| m.label()).collect();
    assert_eq!(
        labels,
        ["taa", "taa_fast", "hash_cache", "hash_cache_secondary_hit_taa", "ssc_multi"]
    );
    assert!(s.methods[..4].iter().all(|m| m.spec.spp() == 1.0));
    let h = s.methods[3].spec.get::<hash_cache::HashCacheSettings>().expect("HashCache settings");
    assert_eq!((h.capacity, h.probe_limit, h.taa), (1024, 8, true));
}

#[test]
fn duplicate_labels_are_refused_naming_both_entries() {
    let text = "Scenario(scene: Builtin(\"cornell_box\"), resolution: (32, 18), frames: 2,\n  methods: [\n    Nirc(spp: 1, predictor: Blend),\n    Nirc(spp: 1, predictor: Blend, cache: (seed: 9)),\n  ])";
    let scenario = sim::Scenario::from_ron(text, Path::new("dup.ron")).unwrap();
    let e = RunSpec::from_scenario(scenario, &Overrides::default()).unwrap_err().to_string();
    assert!(e.starts_with("dup.ron:4:5:"), "{e}");
    assert!(e.contains("'nirc_blend_1spp'") && e.contains("dup.ron:3:5"), "{e}");

    // Named apart, they run side by side.
    let named =
        text.replace("predictor: Blend, cache", "name: \"blend_fast\", predictor: Blend, cache");
    let scenario = sim::Scenario::from_ron(&named, Path::new("dup.ron")).unwrap();
    let s =
        RunSpec::from_scenario(scenario, &Overrides::default()).unwrap_or_else(|e| panic!("{e:#}"));
    assert_eq!(
        s.methods.iter().map(|m| m.label()).collect::<Vec<_>>(),
        ["nirc_blend_1spp", "blend_fast"]
    );

    // --spp can make two labels equal too.
    let scenario = sim::Scenario::from_ron(
        "Scenario(scene: Builtin(\"cornell_box\"), resolution: (32, 18), frames: 2, methods: [PathTracing(spp: 1), PathTracing(spp: 4)])",
        Path::new("spp.ron"),
    )
    .unwrap();
    let e = RunSpec::from_scenario(scenario, &Overrides { spp: Some(2), ..Default::default() })
        .unwrap_err()
        .to_string();
    assert!(e.contains("'pt_2spp'") && e.contains("--spp 2"), "{e}");
}

#[test]
fn method_errors_point_into_the_file() {
    let text = "Scenario(scene: Builtin(\"cornell_box\"), resolution: (32, 18), frames: 2,\n  methods: [\n    PathTracing(spp: 1),\n    SampleCache(retrace: Sometimes),\n  ])";
    let scenario = sim::Scenario::from_ron(text, Path::new("bad.ron")).unwrap();
    let e = RunSpec::from_scenario(scenario, &Overrides::default()).unwrap_err().to_string();
    assert!(e.starts_with("bad.ron:4:"), "{e}");
    assert!(e.contains("Sometimes") && e.contains("expected"), "{e}");
    let e = Method::parse("Taa(alpah: 0.2)").unwrap_err();
    assert!(e.contains("alpah"), "{e}");
    let e = Method::parse("Taa(name: \"a/b\")").unwrap_err();
    assert!(e.contains("a/b"), "{e}");
}

#[test]
fn paper_scale_scenarios_parse_with_the_controls_and_the_nrc_batch() {
    // scenarios/paper/ is for GPUs (CI never plays it): check here that each file and its methods
    // parse, with the six methods and NRC's batch.
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("../scenarios/paper");
    let mut count = 0;
    for entry in std::fs::read_dir(&dir).unwrap() {
        let path = entry.unwrap().path();
        let spec = RunSpec::load(&path, &Default::default())
            .unwrap_or_else(|e| panic!("{}: {e:#}", path.display()));
        let labels: Vec<String> = spec.methods.iter().map(|m| m.label()).collect();
        assert_eq!(
            labels,
            [
                "nirc_ema_1spp",
                "nirc_highlr_1spp",
                "nirc_blend_1spp",
                "nirc_switch_1spp",
                "nirc_fixed50_1spp",
                "pt_1spp"
            ],
            "{}",
            path.display()
        );
        for m in &spec.methods {
            if let Some(n) = m.spec.get::<nirc::plugin::NircSettings>() {
                assert_eq!(
                    (n.pretrain_frames, n.paths.train_records),
                    (5000, 16384),
                    "{}",
                    path.display()
                );
            }
        }
        count += 1;
    }
    assert_eq!(count, 3);
}

#[test]
fn termination_text_parses_with_the_paper_defaults_and_refuses_unknown_fields() {
    use termination::TerminationRule;
    let m = Method::parse("Termination(rule: MseMinimisation(s: 100.0))").unwrap();
    assert_eq!(m.label(), "termination_mse_100");
    let s = m.spec.get::<termination::TerminationSettings>().expect("Termination settings");
    assert_eq!(s.rule, TerminationRule::MseMinimisation { s: 100.0, margin: 1.1, bias_clamp: 0.1 });
    assert_eq!((s.store_probability, s.survival), (0.01, 1.0));
    let e = Method::parse("Termination(rule: VarianceBounding(t: 0.1, tt: 1.0))").unwrap_err();
    assert!(e.contains("tt"), "{e}");
    let e = Method::parse("Termination(rule: VarianceBounding(t: 0.1), samples: 4)").unwrap_err();
    assert!(e.contains("samples"), "{e}");
}
