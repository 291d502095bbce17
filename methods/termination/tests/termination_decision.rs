//! The termination decision at one vertex (termination::decide) on hand-computed cases.

use termination::{
    Decision, LocalStats, PathState, TerminationRule, arrive_area_spread, decide, path_threshold,
};

fn stats(variance: f64, bias2: f64, deferred_bias2: f64) -> LocalStats {
    LocalStats { radiance: 2.0, variance, continuation2: 1.0, bias2, deferred_bias2 }
}

#[test]
fn variance_bounding_blends_the_overshooting_vertex_with_eq5_alpha() {
    let rule = TerminationRule::VarianceBounding { t: 1.0, relative: false };
    let mut s = PathState {
        throughput2: 4.0,
        path_variance: 0.5,
        threshold: 1.0,
        vertex: 2,
        ..Default::default()
    };
    // P = 4 · 0.1 = 0.4: 0.9 <= 1, continue.
    assert_eq!(decide(&rule, 1.0, &mut s, &stats(0.1, 0.0, 0.0)), Decision::Continue);
    assert!((s.path_variance - 0.9).abs() < 1e-12);
    // P = 4 · 0.1 = 0.4 again: 1.3 > 1, α = sqrt(0.1 / 0.4) = 0.5.
    let d = decide(&rule, 1.0, &mut s, &stats(0.1, 0.0, 0.0));
    assert!(matches!(d, Decision::Blend { alpha } if (alpha - 0.5).abs() < 1e-12), "{d:?}");
    // Roulette of survival 0.5 on the continuation (E[B²] = 1): 0.1 + (1/0.5 − 1) · 1 = 1.1.
    assert!((stats(0.1, 0.0, 0.0).variance_with_roulette(0.5) - 1.1).abs() < 1e-12);
}

#[test]
fn relative_threshold_scales_with_the_first_cache_value() {
    let relative = TerminationRule::VarianceBounding { t: 0.5, relative: true };
    let absolute = TerminationRule::VarianceBounding { t: 0.5, relative: false };
    assert_eq!(path_threshold(&relative, Some(3.0)), 4.5);
    assert_eq!(path_threshold(&absolute, Some(3.0)), 0.5);
    // No filled record at the first hit: no brightness to scale, the path is path traced
    // (a threshold of 0 would cut it at its first filled vertex).
    assert_eq!(path_threshold(&relative, None), f64::INFINITY);
    assert_eq!(path_threshold(&absolute, None), 0.5);
    let mut s = PathState {
        throughput2: 1.0,
        threshold: path_threshold(&relative, None),
        vertex: 2,
        ..Default::default()
    };
    assert_eq!(decide(&relative, 1.0, &mut s, &stats(1e6, 0.0, 0.0)), Decision::Continue);
}

#[test]
fn mse_minimisation_compares_current_and_deferred_mse() {
    let rule = TerminationRule::MseMinimisation { s: 10.0, margin: 1.0, bias_clamp: 0.1 };
    // current = 0 + 1 · 0.5; deferred = (0 + 1 · 2) / 10 + min(0.01, 0.05) = 0.21: continue.
    let mut s = PathState { throughput2: 1.0, vertex: 1, ..Default::default() };
    assert_eq!(decide(&rule, 1.0, &mut s, &stats(2.0, 0.5, 0.01)), Decision::Continue);
    assert!((s.path_variance - 2.0).abs() < 1e-12);
    // current = 2 / 10 + 0.05 = 0.25; deferred = (2 + 3) / 10 + 0.001 = 0.501: terminate.
    assert_eq!(decide(&rule, 1.0, &mut s, &stats(3.0, 0.05, 0.001)), Decision::Terminate);
    // The clamp: a deferred bias above the local one is cut to 10% of it (over the margin),
    // so at a huge s the path continues even though the raw deferred bias is larger.
    let rule = TerminationRule::MseMinimisation { s: 1e12, margin: 1.1, bias_clamp: 0.1 };
    let mut s = PathState { throughput2: 1.0, vertex: 1, ..Default::default() };
    assert_eq!(decide(&rule, 1.0, &mut s, &stats(2.0, 0.5, 5.0)), Decision::Continue);
}

/// At the primary vertex the path variance is 0 and the throughput cancels (§4.3: "termination
/// is entirely dependent on the local statistics"); with the deferred bias clamped (a next record
/// at least as biased as this one), current = B², deferred = P/s + c·B²/m, and the rule ends the
/// path iff B² <= m·(P/s + c·B²/m), i.e. iff the record's squared bias is at most
/// m / (s·(1 − c)) of its local variance: 1.1 / (100 · 0.9) = 1.22% with the paper's s = 100,
/// margin 1.1 and the 90% clamp. Table 1's MSE path length of 1.00 needs records that unbiased.
#[test]
fn mse_minimisation_ends_at_the_first_vertex_below_the_closed_form_bias_share() {
    // Hand-computed: s = 100, margin 1.1, clamp 0.1, P = 1: the share is 0.0122.
    let rule = TerminationRule::MseMinimisation { s: 100.0, margin: 1.1, bias_clamp: 0.1 };
    let at_first = |bias2: f64, deferred: f64, throughput2: f64| {
        let mut s = PathState { throughput2, vertex: 1, ..Default::default() };
        decide(&rule, 1.0, &mut s, &stats(1.0, bias2, deferred))
    };
    // B² = 0.012: current 0.012 <= 1.1 · (0.01 + 0.0012/1.1) = 0.0122: terminate.
    assert_eq!(at_first(0.012, 1.0, 1.0), Decision::Terminate);
    // B² = 0.0123: 0.0123 > 1.1 · 0.01 + 0.00123 = 0.01223: continue.
    assert_eq!(at_first(0.0123, 1.0, 1.0), Decision::Continue);
    // The throughput cancels: the same decisions at any prefix weight.
    assert_eq!(at_first(0.012, 1.0, 37.0), Decision::Terminate);
    assert_eq!(at_first(0.0123, 1.0, 37.0), Decision::Continue);
    // A next record less biased than the clamp: B² <= 1.1 · (0.01 + 0.0005) = 0.01155 only.
    assert_eq!(at_first(0.0115, 0.0005, 1.0), Decision::Terminate);
    assert_eq!(at_first(0.0116, 0.0005, 1.0), Decision::Continue);

    // The closed form m / (s (1 − c)) over parameters, just below and just above it, and with
    // roulette of survival q (local variance V + (1/q − 1) E[B²], deferred bias / q, still
    // clamped).
    for s_target in [1.0, 10.0, 100.0, 1000.0] {
        for margin in [1.0, 1.1, 2.0] {
            for clamp in [0.1, 0.5] {
                for q in [1.0, 0.2] {
                    let rule =
                        TerminationRule::MseMinimisation { s: s_target, margin, bias_clamp: clamp };
                    let base = stats(2.0, 0.0, 0.0);
                    let p = base.variance_with_roulette(q);
                    let share = margin / (s_target * (1.0 - clamp));
                    for (factor, expected) in
                        [(1.0 - 1e-6, Decision::Terminate), (1.0 + 1e-6, Decision::Continue)]
                    {
                        let bias2 = share * p * factor;
                        let mut st =
                            PathState { throughput2: 3.0, vertex: 1, ..Default::default() };
                        let d = decide(&rule, q, &mut st, &stats(2.0, bias2, 10.0 * bias2));
                        assert_eq!(
                            d,
                            expected,
                            "s {s_target}, margin {margin}, clamp {clamp}, q {q}: B²/P = {}",
                            bias2 / p
                        );
                    }
                }
            }
        }
    }
}

#[test]
fn area_spread_never_ends_at_the_primary_vertex_and_ends_past_c() {
    let rule = TerminationRule::AreaSpread { c: 0.01 };
    let mut s = PathState { vertex: 1, ..Default::default() };
    // Primary: d² = 4π, cos 1 -> a0 = 1.
    arrive_area_spread(&mut s, 4.0 * std::f64::consts::PI, 0.0, 1.0);
    assert!((s.spread0 - 1.0).abs() < 1e-12);
    assert_eq!(decide(&rule, 1.0, &mut s, &stats(1.0, 0.0, 0.0)), Decision::Continue);
    // Second vertex: sqrt(0.0004 / (1 · 1)) = 0.02, spread 0.0004 < 0.01: continue.
    s.vertex = 2;
    arrive_area_spread(&mut s, 0.0004, 1.0, 1.0);
    assert_eq!(decide(&rule, 1.0, &mut s, &stats(1.0, 0.0, 0.0)), Decision::Continue);
    // Third: + sqrt(0.01 / (0.5 · 0.5)) = 0.2 -> 0.22² = 0.0484 > 0.01: terminate.
    s.vertex = 3;
    arrive_area_spread(&mut s, 0.01, 0.5, 0.5);
    assert_eq!(decide(&rule, 1.0, &mut s, &stats(1.0, 0.0, 0.0)), Decision::Terminate);
}

#[test]
fn the_two_ends() {
    let mut s = PathState { throughput2: 1.0, vertex: 1, ..Default::default() };
    assert_eq!(
        decide(&TerminationRule::FirstVertex, 1.0, &mut s, &stats(1e9, 1e9, 0.0)),
        Decision::Terminate
    );
    assert_eq!(
        decide(&TerminationRule::PathTracing, 1.0, &mut s, &stats(1e9, 1e9, 0.0)),
        Decision::Continue
    );
    // t = 0: the first vertex already overshoots, α = 0: terminate.
    let mut s = PathState { throughput2: 1.0, vertex: 1, ..Default::default() };
    assert_eq!(
        decide(
            &TerminationRule::VarianceBounding { t: 0.0, relative: false },
            1.0,
            &mut s,
            &stats(0.5, 0.0, 0.0)
        ),
        Decision::Terminate
    );
}

#[test]
fn bad_rules_are_refused_with_their_parameter() {
    let e = TerminationRule::VarianceBounding { t: -1.0, relative: false }.validate().unwrap_err();
    assert!(e.contains("VarianceBounding t"), "{e}");
    let e = TerminationRule::MseMinimisation { s: 0.5, margin: 1.1, bias_clamp: 0.1 }
        .validate()
        .unwrap_err();
    assert!(e.contains("sample target"), "{e}");
}
