//! `flicker reproduce PAPER --scale smoke` end to end, one test per paper (so that the papers
//! play side by side on the test runner's threads): every claim of the paper gets a verdict,
//! every claim the file does not declare "not comparable" gets per-seed values, and a case whose
//! run fails is an error with nothing written. `every_claims_file_has_its_test` keeps the list
//! of papers equal to the claims files, so every claim of every paper is still played.
//!
//! Determinism: the papers in `REPLAYED` are played twice with the same seeds (the second time
//! with fresh reference and NIRC warm-start caches) and must give the same numbers, bit for bit,
//! and the same verdicts (measured times excepted). Replayed are the papers whose methods no
//! other test plays twice end to end (subsurface scattering; the volume methods, media and the
//! CPU computations of the jackknife paper); the others' methods have their own bit-for-bit tests
//! (NIRC: `methods/nirc/tests/integrator.rs`, `sparse_updates.rs`, and a warm-started cache
//! played twice from fresh caches, `tests/cli.rs`; the sample cache, TAA, path
//! tracing: `methods/sample_cache/tests/sample_cache.rs`, `tests/cli.rs`; termination:
//! `methods/termination/tests/termination_cache.rs`, `methods/termination/tests/termination_shared.rs`).
//!
//! The claims that smoke scale reproduces are also regression gates (they were the papers
//! suite's gates): each claim in `GATES` must be judged "reproduced", so a method that gets
//! worse fails here. Each claim's margin is its claims file's smallest effect that matters (from
//! the paper or an argued threshold), not this list's.

use std::path::{Path, PathBuf};

use tools::reproduce::{Claims, ReproduceOptions, ReproduceOutcome, Scale, reproduce};

/// (paper, claim) that `--scale smoke` reproduces, every one not judged on a measured time.
const GATES: &[(&str, &[&str])] = &[
    (
        "jackknife-transmittance",
        &[
            "jackknife_less_bias",
            "naive_slightly_lower_std",
            "table1_jackknife_unbiased",
            "table1_naive_lower_std",
            "fig10_track_length_std",
            "fig10_ratio_tracking_std",
            "fig10_unbiased_ray_marching_fails",
            "fig12_mis_below_free_flight",
            "fig8b_biased_ray_marching_more_bias",
            "naive_slightly_lower_std_explosion",
            "sec63_supervoxel_12_less_bias",
            "fig10d_unbiased_ray_marching_std_n10",
        ],
    ),
    ("realtime-sss-thesis", &["adaptive_fewer_samples_than_fixed"]),
    ("reliability-weighted-nirc", &["cache_beats_path_tracing"]),
    (
        "stable-sample-caching",
        &[
            "flickers_less_than_taa",
            "flickers_less_than_1spp",
            "adaptive_traces_less_than_multi",
            "adaptive_shading_budget",
        ],
    ),
    (
        "variance-trading-termination",
        &[
            "length_grows_with_t_corridor",
            "length_grows_with_t_upper",
            "area_spread_length_corridor",
            "fig4_variance_meets_t",
            "fig4_bound_detaches",
            "fig5_own_target_below_fewer",
            "fig5_own_target_below_more",
            "fig5_beats_path_tracing",
            "dynamic_short_history_reacts",
            "dynamic_bias_estimate_lingers",
        ],
    ),
];

/// Every paper this file plays, one test each (`every_claims_file_has_its_test`).
const PAPERS: &[&str] = &[
    "jackknife-transmittance",
    "realtime-sss-thesis",
    "reliability-weighted-nirc",
    "stable-sample-caching",
    "variance-trading-termination",
];

/// The papers played a second time for determinism (see the file's comment).
const REPLAYED: &[&str] = &["jackknife-transmittance", "realtime-sss-thesis"];

fn root() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).parent().unwrap().to_path_buf()
}

fn temp(name: &str) -> tempfile::TempDir {
    tempfile::Builder::new().prefix(&format!("flicker-reproduce-{name}-")).tempdir().unwrap()
}

fn options(claims_dir: PathBuf, paper: &str, out: PathBuf, cache: &Path) -> ReproduceOptions {
    ReproduceOptions {
        paper: paper.into(),
        claims_dir,
        scale: Scale::Smoke,
        seeds: None,
        out: Some(out),
        cache_dir: Some(cache.to_path_buf()),
        progress: false,
    }
}

/// Plays `paper` at smoke scale (twice where it is in `REPLAYED`) and checks its claims: each
/// one an outcome, values where comparable, a line in reproduce.md, the same bits on the replay,
/// and its gates reproduced.
fn plays(paper: &str) {
    let tmp = temp(paper);
    let dir = tmp.path().to_path_buf();
    let claims_dir = root().join("claims");
    let started = std::time::Instant::now();
    let first =
        reproduce(&options(claims_dir.clone(), paper, dir.join("first"), &dir.join("cache")))
            .unwrap_or_else(|e| panic!("reproduce {paper} --scale smoke: {e:#}"));
    eprintln!("{paper}: first run {:.1} s\n{}", started.elapsed().as_secs_f64(), first.markdown);

    // Every claim of the file, in file order, and nothing else.
    let c = Claims::load(&claims_dir.join(format!("{paper}.ron"))).unwrap();
    let expected: Vec<(String, String)> =
        c.claims.iter().map(|claim| (c.paper.clone(), claim.id.clone())).collect();
    let got: Vec<(String, String)> =
        first.claims.iter().map(|c| (c.paper.clone(), c.id.clone())).collect();
    assert_eq!(got, expected, "one outcome per claim");
    for c in &first.claims {
        if !c.declared_not_comparable {
            assert!(
                !c.judged.values.is_empty() && c.judged.values.iter().all(|v| v.is_finite()),
                "{} {}: no values ({:?}: {})",
                c.paper,
                c.id,
                c.judged.verdict,
                c.judged.flicker
            );
        }
    }
    let md = std::fs::read_to_string(dir.join("first/reproduce.md")).unwrap();
    assert!(first.claims.iter().all(|c| md.contains(&format!("| {}: ", c.id))), "{md}");
    let gates = GATES.iter().find(|(p, _)| *p == paper).map_or(&[][..], |(_, ids)| ids);
    let failed: Vec<String> = gates
        .iter()
        .filter_map(|id| {
            let c = first.claims.iter().find(|c| c.paper == paper && c.id == *id);
            match c {
                None => Some(format!("{paper} {id}: no such claim")),
                Some(c) if c.timing => Some(format!("{paper} {id}: judged on a time")),
                Some(c) if c.judged.verdict.name() != "reproduced" => Some(format!(
                    "{paper} {id}: {} ({})",
                    c.judged.verdict.name(),
                    c.judged.flicker
                )),
                Some(_) => None,
            }
        })
        .collect();

    if REPLAYED.contains(&paper) {
        replayed_gives_the_same_bits(paper, &first, &claims_dir, &dir);
    }
    // The gates last, so that a changed verdict still shows whether the numbers repeat.
    assert!(failed.is_empty(), "gates no longer reproduced at smoke scale:\n{}", failed.join("\n"));
}

/// The same seeds again, independently: fresh reference and NIRC warm-start caches, so
/// references and pre-training are made again rather than read back. Every method is
/// bit-reproducible on one adapter, so every number (measured times excepted) is the same.
fn replayed_gives_the_same_bits(
    paper: &str,
    first: &ReproduceOutcome,
    claims_dir: &Path,
    dir: &Path,
) {
    let started = std::time::Instant::now();
    let second = reproduce(&options(
        claims_dir.to_path_buf(),
        paper,
        dir.join("second"),
        &dir.join("fresh"),
    ))
    .expect("second run");
    eprintln!("{paper}: second run {:.1} s", started.elapsed().as_secs_f64());
    assert!(dir.join("fresh").is_dir(), "the second run made its own caches");
    assert_eq!(second.claims.len(), first.claims.len());
    let mut differ = Vec::new();
    for (a, b) in first.claims.iter().zip(&second.claims) {
        assert_eq!((&a.paper, &a.id), (&b.paper, &b.id));
        assert_eq!(a.judged.values.len(), b.judged.values.len(), "{} {}", a.paper, a.id);
        if a.timing {
            continue;
        }
        // Bit for bit: the same f64s (to_bits, so that a NaN would count as equal to itself).
        let bits = |v: &[f64]| v.iter().map(|x| x.to_bits()).collect::<Vec<_>>();
        if bits(&a.judged.values) != bits(&b.judged.values) || a.judged.verdict != b.judged.verdict
        {
            differ.push(format!(
                "{} {}: {:?} ({}) against {:?} ({})",
                a.paper, a.id, a.judged.values, a.judged.flicker, b.judged.values, b.judged.flicker
            ));
        }
    }
    assert!(
        differ.is_empty(),
        "two independent runs with the same seeds differ:\n{}",
        differ.join("\n")
    );
}

#[test]
fn every_claims_file_has_its_test() {
    let mut files: Vec<String> = std::fs::read_dir(root().join("claims"))
        .unwrap()
        .map(|e| e.unwrap().path())
        .filter(|p| p.extension().is_some_and(|e| e == "ron"))
        .map(|p| Claims::load(&p).unwrap().paper)
        .collect();
    files.sort();
    assert_eq!(files, PAPERS, "each claims file needs its test in this file");
    for (paper, _) in GATES {
        assert!(PAPERS.contains(paper), "gates of {paper}, which is not played");
    }
    for paper in REPLAYED {
        assert!(PAPERS.contains(paper), "replayed {paper}, which is not played");
    }
}

// One test per paper, numbered longest first: the test runner starts tests in the order of their
// names, and the NIRC paper takes about as long as all the others together.
#[test]
fn paper_2_jackknife_transmittance() {
    plays("jackknife-transmittance");
}

#[test]
fn paper_3_realtime_sss_thesis() {
    plays("realtime-sss-thesis");
}

#[test]
fn paper_1_reliability_weighted_nirc() {
    plays("reliability-weighted-nirc");
}

#[test]
fn paper_5_stable_sample_caching() {
    plays("stable-sample-caching");
}

#[test]
fn paper_4_variance_trading_termination() {
    plays("variance-trading-termination");
}

#[test]
fn a_case_whose_run_fails_is_an_error_and_nothing_is_written() {
    let tmp = temp("fails");
    let dir = tmp.path().to_path_buf();
    let claims_dir = dir.join("claims");
    std::fs::create_dir_all(&claims_dir).unwrap();
    // The jackknife claims with a smoke size no adapter has: the file loads (sizes are not an
    // input error of the claims file), the run refuses it.
    // Every case's relative scenario path made absolute (the copy lives elsewhere).
    let cloud = root().join("suites/scenarios/papers_volume_cloud.ron");
    let text = std::fs::read_to_string(root().join("claims/jackknife-transmittance.ron"))
        .unwrap()
        .replace("\"../", &format!("\"{}/", root().display()))
        .replace(
            &format!("\"{}\"", cloud.display()),
            &format!("\"{}\", smoke: (resolution: (1000000, 1))", cloud.display()),
        );
    assert!(text.contains("1000000"), "the cloud case is in the file");
    std::fs::write(claims_dir.join("jackknife-transmittance.ron"), text).unwrap();
    let out = dir.join("out");
    let e = reproduce(&options(claims_dir, "all", out.clone(), &dir.join("cache")))
        .err()
        .expect("a failing case is an error");
    let e = format!("{e:#}");
    assert!(e.contains("case 'cloud'"), "{e}");
    assert!(!out.join("reproduce.md").exists() && !out.join("reproduce.html").exists());
}
