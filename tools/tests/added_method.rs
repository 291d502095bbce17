//! A method added through the registry alone: an exponential moving average of 1-spp path
//! tracing, defined here, registered with `playback::methods::register`, named in a scenario,
//! played, and seen in the schedule, frames.csv and the report like a shipped method; with a
//! statistic of its own (declared with its plugin) in frames.csv, its chart in the report, and a
//! claim on that statistic that `flicker reproduce` reads, judges and reports.

use std::path::{Path, PathBuf};
use std::time::Instant;

use anyhow::Result;
use bevy_ecs::prelude::*;
use frame::{FrameClock, GpuDevice, GpuScene, MethodFrame, MethodInfo, Run, Stage};
use playback::methods::{MethodChart, MethodOutput, MethodPlugin, Statistic, register};
use playback::play::{RunOptions, run_spec};
use playback::scenario::{Overrides, RunSpec};
use render::path_tracer::PathTracer;
use serde::{Deserialize, Serialize};

/// `EmaPathTracing(alpha: 0.5)`: each frame's 1-spp image blended into the last with weight α.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
struct EmaSettings {
    alpha: f32,
}

impl Default for EmaSettings {
    fn default() -> Self {
        Self { alpha: 0.5 }
    }
}

#[derive(Component)]
struct EmaState {
    alpha: f32,
    average: Option<Vec<[f32; 4]>>,
    tracer: PathTracer,
}

/// Rec. 709 luminance.
fn luminance(p: &[f32; 4]) -> f64 {
    0.2126 * p[0] as f64 + 0.7152 * p[1] as f64 + 0.0722 * p[2] as f64
}

/// The method's own statistic: the mean over pixels of |Y(average) − Y(previous average)|, how
/// far the average moved this frame (none on the first frame).
fn step(previous: &[[f32; 4]], average: &[[f32; 4]]) -> f64 {
    let sum: f64 =
        previous.iter().zip(average).map(|(p, a)| (luminance(a) - luminance(p)).abs()).sum();
    sum / average.len() as f64
}

struct EmaPlugin;

impl MethodPlugin for EmaPlugin {
    type Settings = EmaSettings;
    const NAME: &'static str = "EmaPathTracing";
    const STATISTICS: &'static [Statistic] =
        &[Statistic::frames("EmaStep", "ema_step", "mean luminance step of the average", "")];
    const CHARTS: &'static [MethodChart] =
        &[MethodChart::Column { column: "ema_step", label: "EMA: mean luminance step" }];

    fn label(settings: &EmaSettings) -> String {
        format!("ema_pt_{}", settings.alpha)
    }

    fn spp(_settings: &EmaSettings) -> f64 {
        1.0
    }

    fn temporal_window(settings: &EmaSettings) -> Option<f64> {
        Some(playback::methods::temporal_window::exponential(settings.alpha as f64))
    }

    fn add_systems(schedule: &mut Schedule) {
        schedule.add_systems(ema_render.in_set(Stage::Render));
    }

    fn spawn(world: &mut World, entity: Entity, settings: &EmaSettings) -> Result<()> {
        anyhow::ensure!(settings.alpha > 0.0 && settings.alpha <= 1.0, "alpha in (0, 1]");
        let tracer =
            PathTracer::new(&world.resource::<GpuDevice>().0, &world.resource::<GpuScene>().0)?;
        world.entity_mut(entity).insert(EmaState { alpha: settings.alpha, average: None, tracer });
        Ok(())
    }
}

fn ema_render(
    gpu: Res<GpuDevice>,
    gpu_scene: Res<GpuScene>,
    run: Res<Run>,
    clock: Res<FrameClock>,
    mut methods: Query<(&mut EmaState, &MethodInfo, &mut MethodFrame)>,
) -> Result<(), BevyError> {
    for (mut state, _info, mut frame) in &mut methods {
        let start = Instant::now();
        let out = state.tracer.render(&gpu.0, &gpu_scene.0, 1, run.scenario.seed, clock.global)?;
        let alpha = state.alpha;
        let (average, stats) = match state.average.take() {
            None => (out.radiance.clone(), vec![]),
            Some(previous) => {
                let average: Vec<[f32; 4]> = previous
                    .iter()
                    .zip(&out.radiance)
                    .map(|(p, c)| std::array::from_fn(|k| alpha * c[k] + (1.0 - alpha) * p[k]))
                    .collect();
                let stats = vec![("ema_step".to_string(), step(&previous, &average))];
                (average, stats)
            }
        };
        state.average = Some(average.clone());
        let mut output =
            MethodOutput::timed(average, out.gbuffer.motion, &out.timings, out.rays, out.shaded);
        output.stats = stats;
        frame.output = Some(output);
        frame.add_cpu(start);
    }
    Ok(())
}

fn read_exr(path: &Path) -> Vec<[f32; 4]> {
    let image = image::open(path).unwrap_or_else(|e| panic!("{}: {e}", path.display()));
    image.to_rgba32f().pixels().map(|p| p.0).collect()
}

#[test]
fn a_method_added_through_the_registry_plays_like_a_shipped_one() {
    register::<EmaPlugin>().unwrap();
    // A second registration under the same name is refused, as is a shipped name.
    assert!(register::<EmaPlugin>().is_err());

    let tmp = tempfile::tempdir().unwrap();
    let dir: PathBuf = tmp.path().to_path_buf();
    std::fs::create_dir_all(&dir).unwrap();
    let file = dir.join("ema.ron");
    std::fs::write(
        &file,
        "Scenario(scene: Builtin(\"cornell_box\"), resolution: (16, 9), frames: 3,\n  reference: (spp: 4, frames: List([2])),\n  methods: [PathTracing(spp: 1), EmaPathTracing(alpha: 0.25), EmaPathTracing(alpha: 0.75)])",
    )
    .unwrap();
    let overrides = Overrides { out: Some(dir.join("run")), ..Default::default() };
    let spec = RunSpec::load(&file, &overrides).expect("scenario with the added method");
    assert_eq!(spec.methods[1].label(), "ema_pt_0.25");
    assert_eq!(spec.methods[1].spec.temporal_window(), Some(7.0));

    // `flicker schedule`: the method and its system in Render.
    let listing = playback::methods::describe_schedule(&spec.methods).unwrap();
    assert!(listing.contains("ema_pt_0.25 (EmaPathTracing)"), "{listing}");
    let render = listing.find("\nRender\n").expect(&listing);
    let learn = listing.find("\nLearn\n").expect(&listing);
    let system = listing.find("ema_render").expect(&listing);
    assert!(render < system && system < learn, "{listing}");

    // An unknown field is an error at the entry's place in the file, as for a shipped method.
    let bad = dir.join("bad.ron");
    std::fs::write(
        &bad,
        "Scenario(scene: Builtin(\"cornell_box\"), resolution: (16, 9), frames: 1,\n  methods: [EmaPathTracing(beta: 0.5)])",
    )
    .unwrap();
    let e = RunSpec::load(&bad, &Overrides::default()).unwrap_err().to_string();
    assert!(e.contains("bad.ron:2:") && e.contains("beta"), "{e}");

    let opts = RunOptions {
        scenario: file.clone(),
        overrides,
        cache_dir: Some(dir.join("cache")),
        progress: false,
    };
    let summary = run_spec(&spec, &opts).expect("run");
    let run = dir.join("run");

    // frames.csv: a row per frame, measured against the reference like the others.
    let csv = std::fs::read_to_string(run.join("frames.csv")).unwrap();
    let rows: Vec<&str> = csv.lines().filter(|l| l.contains("ema_pt_0.25")).collect();
    assert_eq!(rows.len(), 3, "{csv}");
    assert!(summary.records.iter().any(|r| r.method == "ema_pt_0.25" && r.frame == 2));

    // Its statistic is a column of frames.csv: empty on frame 0 (no previous average) and in
    // the other methods' rows, and the step of its frames as written (checked below).
    let header: Vec<&str> = csv.lines().next().unwrap().split(',').collect();
    let column = header.iter().position(|h| *h == "ema_step").expect("an ema_step column");
    let cell = |label: &str, frame: u32| -> Option<f64> {
        let row = csv.lines().find(|l| l.starts_with(&format!("{label},{frame},")))?;
        row.split(',').nth(column).filter(|c| !c.is_empty()).map(|c| c.parse().unwrap())
    };
    assert_eq!(cell("ema_pt_0.25", 0), None);
    assert_eq!(cell("pt_1spp", 1), None);

    // The report names it and draws its chart.
    let html = std::fs::read_to_string(run.join("report.html")).unwrap();
    assert!(html.contains("ema_pt_0.25"));
    assert!(run.join("charts/frames_ema_step.svg").is_file());
    assert!(html.contains("EMA: mean luminance step"), "the chart's title in the report");

    // And it computes what it says: frame 0 is the 1-spp image (same seeds as PathTracing), each
    // later frame α·current + (1 − α)·previous.
    let frames = |label: &str| -> Vec<Vec<[f32; 4]>> {
        (0..3).map(|f| read_exr(&run.join(format!("frames/{label}/{f:04}.exr")))).collect()
    };
    let (pt, ema) = (frames("pt_1spp"), frames("ema_pt_0.25"));
    assert_eq!(ema[0], pt[0]);
    let mut expected = pt[0].clone();
    for f in 1..3 {
        expected = expected
            .iter()
            .zip(&pt[f])
            .map(|(p, c)| std::array::from_fn(|k| 0.25 * c[k] + 0.75 * p[k]))
            .collect();
        for (e, g) in expected.iter().zip(&ema[f]) {
            for k in 0..3 {
                assert!(
                    (e[k] - g[k]).abs() <= 1e-6 * e[k].abs().max(1.0),
                    "frame {f}: {e:?} {g:?}"
                );
            }
        }
        // The statistic is the step between the frames written (f32 EXRs: exact but for the
        // order of the sum; frames.csv keeps 6 decimals).
        let expected = step(&ema[f - 1], &ema[f]);
        let got = cell("ema_pt_0.25", f as u32).expect("a step from frame 1 on");
        assert!(
            expected > 0.0 && (got - expected).abs() <= 5e-7 + 1e-5 * expected,
            "{got} {expected}"
        );
    }

    // A claim on the statistic, in a claims file of its own: `flicker reproduce` plays the case
    // over three seeds, reads the statistic from each run and judges it. The step is α times
    // the distance of the new sample from the average, so α = 0.25 moves the average less than
    // α = 0.75 on every seed.
    let claims = dir.join("claims");
    std::fs::create_dir_all(&claims).unwrap();
    std::fs::write(
        claims.join("ema.ron"),
        format!(
            "Claims(\n    paper: \"ema\",\n    title: \"EMA\",\n    cases: [\n        (name: \"box\", scenario: \"{}\", seeds: [1, 2, 3]),\n    ],\n    claims: [\n        (\n            id: \"smaller_alpha_smaller_steps\",\n            claim: \"A smaller blend weight moves the average less per frame\",\n            source: \"the method's definition\",\n            paper: \"step = alpha |sample - previous average|\",\n            case: \"box\",\n            statistic: (metric: EmaStep, window: Overall),\n            comparison: Below(method: \"ema_pt_0.25\", than: \"ema_pt_0.75\"),\n            smallest_effect: Relative(0.05),\n            smallest_effect_from: \"argued: a step 5% smaller\",\n        ),\n    ],\n)\n",
            file.display()
        ),
    )
    .unwrap();
    let outcome = tools::reproduce::reproduce(&tools::reproduce::ReproduceOptions {
        paper: "ema".into(),
        claims_dir: claims,
        scale: tools::reproduce::Scale::Lab,
        seeds: None,
        out: Some(dir.join("reproduce")),
        cache_dir: Some(dir.join("cache")),
        progress: false,
    })
    .expect("reproduce the added method's claim");
    let claim = &outcome.claims[0];
    assert_eq!(claim.id, "smaller_alpha_smaller_steps");
    assert_eq!(claim.judged.values.len(), 6, "both methods' value per seed");
    assert_eq!(claim.judged.verdict.name(), "reproduced", "{}", claim.judged.flicker);
    assert!(outcome.markdown.contains("ema_step"), "{}", outcome.markdown);
}
