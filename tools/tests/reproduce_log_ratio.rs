//! `LogRatio` claims and the `RmsBias` statistic in claims files: bad ones are errors at the
//! claim's file:line before anything plays; a log ratio is judged on the per-seed ratio of the
//! two methods' values.

use std::path::{Path, PathBuf};

use tools::reproduce::log_ratio::RatioExpectation;
use tools::reproduce::{Claims, Comparison, Effect, Verdict, judge};

fn root() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).parent().unwrap().to_path_buf()
}

/// A claims file in the claims folder's place (so `../scenarios/...` resolves) with one case on
/// line 5 and one claim on line 8; the load's error.
fn error_of(case: &str, claim: &str) -> String {
    let text = format!(
        "Claims(\n    paper: \"x\",\n    title: \"x\",\n    cases: [\n        {case},\n    ],\n    claims: [\n        {claim},\n    ],\n)\n"
    );
    Claims::from_ron(&text, &root().join("claims/bad.ron")).map(|_| ()).unwrap_err().to_string()
}

const EXPLOSION: &str =
    "(name: \"sv\", scenario: \"../scenarios/volume_explosion_supervoxel.ron\", seeds: [1, 2])";
const SHADOW: &str =
    "(name: \"shadow\", scenario: \"../scenarios/volume_shadow.ron\", seeds: [1, 2])";

fn claim(case: &str, metric: &str, a: &str, b: &str, expect: &str) -> String {
    format!(
        "(id: \"c\", claim: \"c\", source: \"Fig. 8\", paper: \"p\", case: \"{case}\", statistic: (metric: {metric}, window: Overall), comparison: LogRatio(method: \"{a}\", to: \"{b}\", expect: {expect}), smallest_effect: Relative(0.05), smallest_effect_from: \"argued\")"
    )
}

#[test]
fn bad_log_ratio_claims_are_errors_at_file_and_line() {
    let ok = claim("sv", "RmsBias", "jackknife_sv16", "naive_sv16", "Below(1.0)");
    let text = format!(
        "Claims(paper: \"x\", title: \"x\", cases: [{}], claims: [{ok}])",
        EXPLOSION.replace("../", "")
    );
    Claims::from_ron(&text, &root().join("x.ron")).expect("a good LogRatio claim loads");
    // A path-traced method records no transmittance bias.
    let rms = claim(
        "shadow",
        "RmsBias",
        "volume_pt_free_flight_16spp",
        "volume_pt_free_flight_shadow_track_length_16spp",
        "Below(1.0)",
    );
    let e = error_of(SHADOW, &rms);
    assert!(e.contains("bad.ron:8") && e.contains("does not record the statistic rms_bias"), "{e}");
    let e = error_of(EXPLOSION, &ok.replace("naive_sv16", "naive_sv20"));
    assert!(e.contains("bad.ron:8") && e.contains("unknown method 'naive_sv20'"), "{e}");
    let e = error_of(EXPLOSION, &ok.replace("Below(1.0)", "Below(0.0)"));
    assert!(e.contains("bad.ron:8") && e.contains("expected a factor above 0"), "{e}");
    let near = ok.replace("Below(1.0)", "Near(1.0)").replace("Relative(0.05)", "Absolute(1.5)");
    let e = error_of(EXPLOSION, &near);
    assert!(e.contains("bad.ron:8") && e.contains("no positive ratio"), "{e}");
    // Every claim states its smallest effect, above 0, and where it comes from.
    let e = error_of(EXPLOSION, &ok.replace("Relative(0.05)", "Relative(0.0)"));
    assert!(e.contains("bad.ron:8") && e.contains("expected a share between 0 and 1"), "{e}");
    let e = error_of(
        EXPLOSION,
        &ok.replace("smallest_effect_from: \"argued\"", "smallest_effect_from: \" \""),
    );
    assert!(e.contains("bad.ron:8") && e.contains("smallest_effect_from is empty"), "{e}");
    let e = error_of(EXPLOSION, &ok.replace("smallest_effect: Relative(0.05), ", ""));
    assert!(e.contains("bad.ron:8") && e.contains("smallest_effect"), "{e}");
    let e = error_of(EXPLOSION, &ok.replace("Below(1.0)", "Above(1.0)"));
    assert!(e.contains("bad.ron:8"), "{e}");
    // A log ratio of a logarithmic score means nothing.
    let psnr = claim(
        "shadow",
        "Psnr",
        "volume_pt_free_flight_16spp",
        "volume_pt_free_flight_shadow_track_length_16spp",
        "Below(1.0)",
    );
    let e = error_of(SHADOW, &psnr);
    assert!(e.contains("bad.ron:8") && e.contains("logarithmic score"), "{e}");
}

#[test]
fn a_log_ratio_is_judged_on_the_per_seed_ratio_of_the_same_runs() {
    let c = |expect| Comparison::LogRatio {
        method: "jackknife".into(),
        to: "naive".into(),
        expect,
        confidence: 0.95,
    };
    // The naive estimate's bias 2.9, 3.0, 3.1 times the jackknife's, at biases that differ
    // tenfold between seeds: within "roughly three" (3 ± 0.5) and the jackknife below it.
    let jackknife = vec![0.001, 0.01, 0.005];
    let naive: Vec<f64> = jackknife.iter().zip([2.9, 3.0, 3.1]).map(|(x, r)| x * r).collect();
    let per_seed = |m: &str, _: Option<&tools::suite::window::Window>| match m {
        "jackknife" => Ok(jackknife.clone()),
        "naive" => Ok(naive.clone()),
        _ => Err("not in the run".to_string()),
    };
    let three = Comparison::LogRatio {
        method: "naive".into(),
        to: "jackknife".into(),
        expect: RatioExpectation::Near(3.0),
        confidence: 0.95,
    };
    let half = Effect::Absolute(0.5);
    let j = judge(&three, &half, &per_seed);
    assert_eq!(j.verdict, Verdict::Reproduced, "{}", j.flicker);
    let rel = Effect::Relative(0.05);
    let j = judge(&c(RatioExpectation::Below(1.0)), &rel, &per_seed);
    assert_eq!(j.verdict, Verdict::Reproduced, "{}", j.flicker);
    // A third of the naive's bias is 0.32 at best: not below 0.3 less 5%.
    let j = judge(&c(RatioExpectation::Below(0.3)), &rel, &per_seed);
    assert_eq!(j.verdict, Verdict::NotReproduced, "{}", j.flicker);
    // The differences of these values would not show the factor (their spread is the seeds').
    let below =
        Comparison::Below { method: "jackknife".into(), than: "naive".into(), confidence: 0.95 };
    assert!(matches!(judge(&below, &rel, &per_seed).verdict, Verdict::Inconclusive { .. }));
}
