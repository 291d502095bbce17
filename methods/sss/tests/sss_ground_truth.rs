//! The screen-space pass against a path-traced ground truth (support::ground_truth): a half-space of
//! albedo 0.99 under a shadow edge, Burley's d from the walk's own A and ℓ_d (Θ3). As the
//! pass's count grows its result approaches the random walk's exitance to within the bound
//! derived in ground_truth.rs, osc(E)·½·D (D: the radial cdfs' largest gap, measured on
//! independent walks, plus its DKW margin), plus Hoeffding margins for the walk's and the
//! pass's own noise (δ = 1e-3 each); a few samples are further off.

mod support;

use sss::profile::scaling_from_dmfp;
use sss::{SssFrame, SssPassSettings, SssVariant};
use support::ground_truth::{WalkOffsets, dkw_margin, hoeffding_margin};
use support::random_walk::Medium;

const W: u32 = 48;
const H: u32 = 2;
const LIT: f32 = 1.0;
const SHADOW: f32 = 0.1;
const DELTA: f64 = 1e-3;

/// The edge at x = 24 (e depends on x only and is monotone, as the bound needs).
fn frame(d_px: f32) -> SssFrame {
    let irradiance = (0..W * H)
        .map(|i| {
            let e = if i % W < W / 2 { LIT } else { SHADOW };
            [e, e, e, 1.0]
        })
        .collect();
    SssFrame { width: W, height: H, irradiance, d_px: [d_px; 3], focal_px: 0.0, motion: Vec::new() }
}

/// The pass's mean over `frames` frames of `count` Burley samples (analytic inverse, the whole
/// disc: no split), red channel.
fn pass(frame: &SssFrame, count: u32, frames: u32) -> Vec<f64> {
    let settings = SssPassSettings {
        variant: SssVariant::Fixed { count },
        fast_inverse: false,
        split: None,
        ..Default::default()
    };
    let mut sum = vec![0.0; (W * H) as usize];
    for f in 0..frames {
        let (r, _) = sss::screen_pass::step(frame, &settings, f, &[]);
        for (s, r) in sum.iter_mut().zip(&r) {
            *s += r.rgb[0] as f64 / frames as f64;
        }
    }
    sum
}

#[test]
fn the_pass_converges_to_the_random_walk_within_the_profile_gap() {
    let medium = Medium::unit(0.99);
    let ld = medium.diffuse_mean_free_path();
    // Burley's A and d from independent walks (seed 2): d = ℓ_d / s(A) (Θ3, eq. 2.44).
    let probe = WalkOffsets::trace(&medium, 100_000, 2, 1.0);
    let d = ld / scaling_from_dmfp(probe.albedo);
    // Two pixels per d.
    let pixel = d / 2.0;
    let probe = WalkOffsets::trace(&medium, 100_000, 2, pixel);
    let gap = probe.cdf_gap(2.0);
    let gap_bound = gap + dkw_margin(probe.offsets.len(), DELTA);
    let walks = WalkOffsets::trace(&medium, 100_000, 1, pixel);
    let f = frame(2.0);
    let truth: Vec<f64> = walks.truth(&f).iter().map(|t| t[0]).collect();
    let osc = (LIT - SHADOW) as f64;
    let (count, frames) = (4096, 8);
    let converged = pass(&f, count, frames);
    let few = pass(&f, 8, 1);
    let bound = osc * 0.5 * gap_bound
        + hoeffding_margin(walks.offsets.len(), osc, DELTA)
        + hoeffding_margin((count * frames) as usize, osc, DELTA);
    let err = |v: &[f64]| v.iter().zip(&truth).map(|(a, b)| (a - b).abs()).fold(0.0, f64::max);
    let (e_conv, e_few) = (err(&converged), err(&few));
    let row: Vec<String> =
        (16..32).map(|x| format!("{x}: {:.4}/{:.4}", converged[x], truth[x])).collect();
    eprintln!(
        "A walk {:.4}, ℓ_d {ld:.3}, d {d:.3} mfp = 2 px; D = {gap:.4} (+ DKW {:.4}); max |pass − truth|: 8 spp {e_few:.4}, {count} x {frames} {e_conv:.4}; bound {bound:.4}\npass/truth by x: {}",
        probe.albedo,
        gap_bound - gap,
        row.join(", ")
    );
    assert!(e_conv <= bound, "max error {e_conv} over the bound {bound}");
    assert!(
        e_few > e_conv,
        "8 samples ({e_few}) no further off than {count} x {frames} ({e_conv})"
    );
}
