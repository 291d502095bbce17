//! Fig. 7 of variance-trading-termination.txt: variance bounding in the door scene against the
//! absolute threshold t with Russian roulette survival 100%, 60% and 20%, played end to end
//! through `flicker run`'s playback on scenarios/termination_variance_door.ron (32x18, 10% of
//! primary vertices stored, 24 warm-up frames, as termination_relations.rs) over three seeds.
//!
//! The scene is static and every frame is an independent one-path image, so the variance of a
//! pixel's luminance over the recorded frames estimates the variance of the pixel's estimator;
//! its mean over the pixels is the image variance of Fig. 7 (left). The rule bounds each path's
//! accumulated variance Σ P_j by t · radiance_unit² with the cache's own estimates of P_j.
//!
//! Each relation holds over the seeds with a one-sided 95% Student-t bound of the mean per-seed
//! value (testkit::relations::assert_positive), so its margin comes from the spread across seeds.

use std::path::{Path, PathBuf};

use frame::frame_record::FrameRecord;
use frame::output::read_exr;
use frame::run_folder::RunFolder;
use playback::play::{RunOptions, run_spec};
use playback::scenario::{Overrides, RunSpec};

use testkit::relations::assert_positive;

const SEEDS: [u64; 3] = [3, 4, 5];
const SCENARIO: &str = "termination_variance_door.ron";
const FRAMES: u32 = 16;
const THRESHOLDS: [&str; 2] = ["0.01", "1"];

/// Per method: mean path length over the frames, the mean over pixels of the per-pixel
/// variance of luminance over the frames, and the MSE of the mean image over the frames
/// against the converged reference (luminance): squared bias + variance / frames.
struct Measured {
    method: String,
    path_length: f64,
    variance: f64,
    mse: f64,
}

impl Measured {
    /// The squared bias: the MSE less the mean image's variance (and the reference's, which is
    /// below 1/2048 of path tracing's variance).
    fn bias2(&self) -> f64 {
        self.mse - self.variance / f64::from(FRAMES)
    }
}

fn luminance(p: &[f32; 4]) -> f64 {
    f64::from(render::lights::luminance(glam::Vec3::new(p[0], p[1], p[2])))
}

fn play(seed: u64) -> (Vec<Measured>, f64) {
    let file = Path::new(env!("CARGO_MANIFEST_DIR")).join("../..").join("scenarios").join(SCENARIO);
    let tmp = tempfile::tempdir().unwrap();
    let dir = tmp.path().to_path_buf();
    let overrides =
        Overrides { seed: Some(seed), out: Some(dir.join("run")), ..Default::default() };
    let mut spec = RunSpec::load(&file, &overrides).expect("scenario");
    assert_eq!(spec.scenario.frames, FRAMES);
    // K = 4: the lavapipe time this test was sized for (K = 32, the default, costs about 5
    // times the propagation); claims/variance-trading-termination.ron's fig7 cases judge the
    // bound at K = 32 against K = 4.
    for m in &mut spec.methods {
        if let Some(t) = m.spec.get_mut::<termination::TerminationSettings>() {
            t.samples_per_vertex = 4;
        }
    }
    let unit = spec
        .methods
        .iter()
        .find_map(|m| m.spec.get::<termination::TerminationSettings>())
        .expect("a Termination method")
        .radiance_unit;
    let opts = RunOptions {
        scenario: PathBuf::from(&file),
        overrides,
        cache_dir: Some(dir.join("references")),
        progress: false,
    };
    let summary = run_spec(&spec, &opts).expect("run");
    let folder = RunFolder::new(&summary.folder);
    let (_, _, reference) = read_exr(&folder.reference(0, "exr")).expect("reference");
    let reference: Vec<f64> = reference.iter().map(luminance).collect();
    let measured = spec
        .methods
        .iter()
        .map(|m| {
            let method = m.label();
            let images: Vec<Vec<f64>> = (0..FRAMES)
                .map(|f| {
                    let (_, _, px) = read_exr(&folder.frame(&method, f, "exr")).expect("frame");
                    px.iter().map(luminance).collect()
                })
                .collect();
            let n = f64::from(FRAMES);
            let pixels = images[0].len();
            let mean = |p: usize| images.iter().map(|im| im[p]).sum::<f64>() / n;
            let variance = (0..pixels)
                .map(|p| images.iter().map(|im| (im[p] - mean(p)).powi(2)).sum::<f64>() / (n - 1.0))
                .sum::<f64>()
                / pixels as f64;
            let mse =
                (0..pixels).map(|p| (mean(p) - reference[p]).powi(2)).sum::<f64>() / pixels as f64;
            let path_length = mean_stat(&summary.records, &method, "path_length");
            Measured { method, path_length, variance, mse }
        })
        .collect();
    (measured, unit)
}

fn mean_stat(records: &[FrameRecord], method: &str, stat: &str) -> f64 {
    let v: Vec<f64> = records
        .iter()
        .filter(|r| r.method == method)
        .map(|r| r.stats.iter().find(|(k, _)| k == stat).expect("stat").1)
        .collect();
    assert_eq!(v.len(), FRAMES as usize, "{method}: frames");
    v.iter().sum::<f64>() / v.len() as f64
}

fn get<'a>(m: &'a [Measured], method: &str) -> &'a Measured {
    m.iter().find(|x| x.method == method).unwrap_or_else(|| panic!("no {method}"))
}

#[test]
fn variance_bounding_against_t_with_roulette() {
    let runs: Vec<(Vec<Measured>, f64)> = SEEDS.iter().map(|&s| play(s)).collect();
    let unit = runs[0].1;
    // The table (Fig. 7's analogue): per method and seed, path length and image variance, and
    // the variance in units of the bound t · unit².
    for (s, (m, _)) in runs.iter().enumerate() {
        for x in m {
            let t = THRESHOLDS.iter().find(|t| x.method.starts_with(&format!("vb_{t}_")));
            let ratio = t.map(|t| x.variance / (t.parse::<f64>().unwrap() * unit * unit));
            eprintln!(
                "seed {} {:>12}: path length {:.3}, image variance {:.4e}, / bound {}, MSE {:.4e}, bias2 {:.4e}",
                SEEDS[s],
                x.method,
                x.path_length,
                x.variance,
                ratio.map_or("-".into(), |r| format!("{r:.3}")),
                x.mse,
                x.bias2()
            );
        }
    }
    let per_seed =
        |f: &dyn Fn(&[Measured]) -> f64| runs.iter().map(|(m, _)| f(m)).collect::<Vec<_>>();
    let ln = |a: &str, b: &str, f: fn(&Measured) -> f64| {
        let (a, b) = (a.to_string(), b.to_string());
        per_seed(&move |m: &[Measured]| (f(get(m, &a)) / f(get(m, &b))).ln())
    };
    let length = |x: &Measured| x.path_length;
    let variance = |x: &Measured| x.variance;
    for t in THRESHOLDS {
        // Fig. 7: a lower survival probability ends paths earlier at the same t (its roulette
        // variance counts against the bound).
        for q in ["100", "60"] {
            assert_positive(
                &format!("t {t}: ln(path length at survival {q}% / at 20%)"),
                &ln(&format!("vb_{t}_q{q}"), &format!("vb_{t}_q20"), length),
            );
        }
    }
    // At 20% and t = 0.01 the image variance is far below path tracing's (at t = 1 it is 2 to
    // 50 times below, too spread over the seeds for a margin).
    assert_positive(
        "t 0.01: ln(path tracing's image variance / survival 20%'s)",
        &ln("pt_q100", "vb_0.01_q20", variance),
    );
    // At 20% path length and image variance grow with t (Fig. 7, both panels). At 100% and 60%
    // they do not by a margin over the seeds at 32x18: t = 1 runs to path tracing's length
    // (9.6 vertices) in every seed and t = 0.01 already does in one (docs/lab/termination-fig7.md).
    assert_positive(
        "survival 20%: ln(path length at t 1 / at t 0.01)",
        &ln("vb_1_q20", "vb_0.01_q20", length),
    );
    assert_positive(
        "survival 20%: ln(image variance at t 1 / at t 0.01)",
        &ln("vb_1_q20", "vb_0.01_q20", variance),
    );
    // Fig. 7's MSE (the mean image over the frames against the converged reference): at 20%
    // it grows with t, as the paper notes for low survival at high thresholds ("images not
    // being completely converged": the variance / frames outgrows the bias the longer paths
    // remove). The paper's main relation (MSE falls with t as bias falls) does not show by a
    // margin at 100% or 60%: 16 frames leave the mean image's variance above the cache's bias
    // (docs/lab/termination-fig7.md).
    assert_positive(
        "survival 20%: ln(MSE at t 1 / at t 0.01)",
        &ln("vb_1_q20", "vb_0.01_q20", |x: &Measured| x.mse),
    );
    // NOT the paper's: the image variance exceeds the bound t · unit² (the records' local
    // variances, from K = 4 samples per stored vertex, miss the rare paths through the door's
    // gap that make most of a pixel's variance). Asserted as measured; fails if the bound
    // starts to hold (then update docs/lab/termination-fig7.md and this test).
    let bound = 0.01 * unit * unit;
    assert_positive(
        "survival 100%, t 0.01: ln(image variance / t · unit²)",
        &per_seed(&|m: &[Measured]| (get(m, "vb_0.01_q100").variance / bound).ln()),
    );
}

#[test]
fn survival_outside_zero_to_one_is_refused_where_it_stands() {
    for (i, (survival, what)) in [
        ("0.0", "survival must be in (0, 1], got 0"),
        ("1.5", "survival must be in (0, 1], got 1.5"),
    ]
    .into_iter()
    .enumerate()
    {
        let text = format!(
            "Scenario(scene: Builtin(\"cornell_box\"), resolution: (32, 18), frames: 1,\n methods: [Termination(rule: FirstVertex, survival: {survival})])"
        );
        let tmp = tempfile::tempdir().unwrap();
        let out = tmp.path().join(format!("flicker_termination_bad_{i}"));
        let scenario = sim::Scenario::from_ron(&text, Path::new("inline.ron")).unwrap();
        let spec = RunSpec::from_scenario(
            scenario,
            &Overrides { out: Some(out.clone()), ..Default::default() },
        )
        .unwrap();
        let opts = RunOptions {
            scenario: "inline.ron".into(),
            overrides: Overrides::default(),
            cache_dir: Some(out.join("cache")),
            progress: false,
        };
        let e = format!("{:#}", run_spec(&spec, &opts).err().expect("refused"));
        assert!(e.contains("inline.ron:2:") && e.contains(what), "survival {survival}: {e}");
        assert!(!out.exists(), "survival {survival}: {} written", out.display());
    }
}
