//! Claims windows relative to a scenario's events and a case's `by_window` tables: a window
//! whose event the case's scenario does not have at some scale, or that holds no frame, is an
//! error at the claim's (or the case's) file:line when the file loads, before anything plays.

use std::path::{Path, PathBuf};

use tools::reproduce::{Claims, Scale};

fn root() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).parent().unwrap().to_path_buf()
}

/// A claims file in the claims folder's place (so `../scenarios/...` resolves): the case on
/// line 5, the claim on line 8.
fn load(case: &str, claim: &str) -> Result<Claims, String> {
    let text = format!(
        "Claims(\n    paper: \"x\",\n    title: \"x\",\n    cases: [\n        {case},\n    ],\n    claims: [\n        {claim},\n    ],\n)\n"
    );
    Claims::from_ron(&text, &root().join("claims/bad.ron")).map_err(|e| e.to_string())
}

/// The flash scenario: events at frames 12 (flash) and 16 (back), 40 frames.
fn flash(extra: &str) -> String {
    format!(
        "(name: \"flash\", scenario: \"../scenarios/termination_flash_corridor.ron\", seeds: [3, 4]{extra})"
    )
}

fn claim(window: &str, comparison: &str) -> String {
    format!(
        "(id: \"c\", claim: \"c\", source: \"s\", paper: \"p\", case: \"flash\", statistic: (metric: CacheMean, window: {window}), comparison: {comparison}, smallest_effect: Relative(0.05), smallest_effect_from: \"argued\")"
    )
}

const BELOW: &str = "Below(method: \"vb_rel_1\", than: \"vb_rel_1_fast\")";

#[test]
fn windows_relative_to_events_load() {
    let c = load(&flash(""), &claim("Around(event: 1, from: 4, to: 12)", BELOW)).unwrap();
    let rises = "Rises(method: \"vb_rel_1\", from: Around(event: 0, from: -4, to: 0))";
    load(&flash(""), &claim("After(event: 1, frames: 4)", rises)).unwrap();
    assert_eq!(c.cases_for(Scale::Smoke, None).len(), 1);
}

#[test]
fn a_window_on_an_event_the_scenario_lacks_is_an_error_at_the_claim() {
    // The flash scenario has two events (0 and 1).
    let e = load(&flash(""), &claim("After(event: 2, frames: 4)", BELOW)).unwrap_err();
    assert!(
        e.contains("bad.ron:8")
            && e.contains("needs event 2 of case 'flash'")
            && e.contains("frame 12: change material 'glow'"),
        "{e}"
    );
    // The Table 1 corridor has none.
    let corridor = "(name: \"flash\", scenario: \"../suites/scenarios/papers_termination_corridor.ron\", seeds: [3, 4])";
    let e = load(
        corridor,
        &claim("Before(event: 0)", "Below(method: \"vb_rel_0.01\", than: \"vb_rel_1\")"),
    )
    .unwrap_err();
    assert!(e.contains("bad.ron:8") && e.contains("has 0 event(s)"), "{e}");
    // A smaller scale that records too few frames loses the event.
    let e = load(&flash(", smoke: (frames: 14)"), &claim("After(event: 1, frames: 4)", BELOW))
        .unwrap_err();
    assert!(e.contains("bad.ron:8") && e.contains("at smoke scale"), "{e}");
    // A window past the run's end holds no frame.
    let e = load(&flash(", lab: (frames: 20)"), &claim("Around(event: 1, from: 4, to: 12)", BELOW))
        .unwrap_err();
    assert!(
        e.contains("bad.ron:8") && e.contains("holds no recorded frame") && e.contains("lab"),
        "{e}"
    );
    let e = load(&flash(""), &claim("Around(event: 0, from: 2, to: 2)", BELOW)).unwrap_err();
    assert!(e.contains("bad.ron:8") && e.contains("from 2 is not before to 2"), "{e}");
    // A rise's earlier window too.
    let rises = "Rises(method: \"vb_rel_1\", from: Before(event: 3))";
    let e = load(&flash(""), &claim("After(event: 1, frames: 4)", rises)).unwrap_err();
    assert!(e.contains("bad.ron:8") && e.contains("from: window before_event_3"), "{e}");
}

#[test]
fn by_window_tables_are_checked_at_the_case() {
    let ok = claim("Overall", BELOW);
    let by = |b: &str| load(&flash(&format!(", by_window: {b}")), &ok);
    by("(metrics: [Flip, CacheBias2], windows: [Around(event: 0, from: -4, to: 0), After(event: 1, frames: 4)])")
        .unwrap();
    let e = by("(metrics: [Flip], windows: [After(event: 5, frames: 4)])").unwrap_err();
    assert!(e.contains("bad.ron:5") && e.contains("by_window: window after_event_5(4)"), "{e}");
    let e = by("(metrics: [BlendSigma], windows: [Overall])").unwrap_err();
    assert!(
        e.contains("bad.ron:5") && e.contains("no method of the case records blend_sigma"),
        "{e}"
    );
    let e = by("(metrics: [PassMs], windows: [Overall])").unwrap_err();
    assert!(e.contains("bad.ron:5") && e.contains("pass_ms"), "{e}");
    let e = by("(metrics: [], windows: [Overall])").unwrap_err();
    assert!(e.contains("bad.ron:5") && e.contains("at least one metric"), "{e}");
    // A case with only tables is played.
    let claims = by("(metrics: [Flip], windows: [Overall])").unwrap();
    let other = "(name: \"other\", scenario: \"../scenarios/termination_flash_corridor.ron\", seeds: [1, 2], by_window: (metrics: [Flip], windows: [Overall])), (name: \"unused\", scenario: \"../scenarios/termination_flash_corridor.ron\", seeds: [1, 2])";
    let two = load(&format!("{}, {other}", flash("")), &ok).unwrap();
    let played: Vec<String> =
        two.cases_for(Scale::Smoke, None).into_iter().map(|c| c.name).collect();
    assert_eq!(played, ["flash", "other"]);
    assert_eq!(claims.cases_for(Scale::Lab, None).len(), 1);
}

#[test]
fn cache_statistics_are_recorded_by_termination_only() {
    let rotation = "(name: \"flash\", scenario: \"../scenarios/termination_light_rotation_corridor.ron\", seeds: [3, 4])";
    let c = "(id: \"c\", claim: \"c\", source: \"s\", paper: \"p\", case: \"flash\", statistic: (metric: CacheBias2, window: Overall), comparison: Below(method: \"pt_1spp\", than: \"vb_rel_1\"), smallest_effect: Relative(0.05), smallest_effect_from: \"argued\")";
    let e = load(rotation, c).unwrap_err();
    assert!(
        e.contains("bad.ron:8") && e.contains("does not record the statistic cache_bias2"),
        "{e}"
    );
}
