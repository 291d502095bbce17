//! The direct/distant split (Sec. 5.3.1, eqs. 5.14-5.20) and eq. 7.1's bilateral weights on the
//! CPU pass (`screen_pass`; the WGSL pass is held to it by sss_gpu.rs).

use sss::screen_pass::{encode, scatter, step};
use sss::split::{self, R0_PX};
use sss::{PixelHistory, Split, SssFrame, SssPassSettings, SssVariant};

const W: u32 = 24;
const H: u32 = 16;

fn flat(b: [f32; 3], d_px: [f32; 3]) -> SssFrame {
    SssFrame {
        width: W,
        height: H,
        irradiance: vec![[b[0], b[1], b[2], 1.0]; (W * H) as usize],
        d_px,
        focal_px: 0.0,
        motion: Vec::new(),
    }
}

fn close(a: f32, b: f32, rel: f32) -> bool {
    (a - b).abs() <= rel * a.abs().max(b.abs())
}

/// Flat irradiance B: the direct term B·cdf(r0) plus the distant term B·(1 − cdf(r0)) is the
/// unsplit integral B·1 (eq. 5.16 with constant lighting), per channel, for every d, for
/// Burley's γ and a constant γ alike; f32 rounding only.
#[test]
fn flat_irradiance_split_equals_the_unsplit_integral() {
    let b = [0.9, 0.45, 0.2];
    for d_px in [[1.5, 0.8, 0.4], [3.0; 3], [0.6, 2.0, 9.0]] {
        let frame = flat(b, d_px);
        let unsplit = SssPassSettings {
            variant: SssVariant::Fixed { count: 16 },
            split: None,
            ..Default::default()
        };
        for split in [Split { gamma: None, eps_u: 0.0 }, Split { gamma: Some(0.3), eps_u: 0.0 }] {
            let with = SssPassSettings { split: Some(split), ..unsplit };
            for (x, y) in [(0, 0), (11, 7), (23, 15), (5, 12)] {
                let a = scatter(&frame, &unsplit, None, 2, x, y, 16);
                let s = scatter(&frame, &with, None, 2, x, y, 16);
                for c in 0..3 {
                    assert!(close(a.rgb[c], b[c], 1e-6), "unsplit {d_px:?} {c}: {:?}", a.rgb);
                    assert!(close(s.rgb[c], b[c], 1e-6), "split {split:?} {d_px:?}: {:?}", s.rgb);
                    // The split's parts: (1 − γ)B and γB.
                    let g = split.gamma.unwrap_or(1.0 - split::cdf(R0_PX, d_px[c]));
                    assert!(close(s.direct[c], (1.0 - g) * b[c], 1e-6), "{:?}", s.direct);
                }
            }
        }
    }
}

/// Distant radii start at r0: u is drawn from (cdf(r0), 1] (eq. 5.17), so with the analytic
/// inverse no sample falls inside the texel's own disc.
#[test]
fn distant_samples_start_at_r0() {
    let d = 1.7;
    let u0 = split::cdf(R0_PX, d);
    for k in 0..1000 {
        let xi = k as f32 / 1000.0;
        let r = sss::sampling::sample_radius(split::distant_u(xi, u0), d, false);
        assert!(r >= R0_PX * (1.0 - 1e-4), "xi {xi}: r {r} < r0 {R0_PX}");
    }
}

/// Eq. 5.20 / Algorithm 3 lines 1-2: where γ < ε_u no distant samples are taken, the output is
/// the direct term alone and no history is kept; above ε_u the pass samples.
#[test]
fn gamma_under_eps_u_takes_no_distant_samples() {
    let b = [0.5, 0.5, 0.5];
    // d = 0.05 px: cdf(r0) ≈ 1, γ ≈ 0.75 e^{-4.7} = 0.0068 < 0.01.
    let tiny = flat(b, [0.05; 3]);
    let gamma = 1.0 - split::cdf(R0_PX, 0.05);
    assert!(gamma < 0.01 && gamma > 0.0, "{gamma}");
    let s = SssPassSettings::default();
    let (r, h) = step(&tiny, &s, 0, &[]);
    for (r, h) in r.iter().zip(&h) {
        assert_eq!(r.count, 0);
        assert!(close(r.rgb[0], (1.0 - gamma) * 0.5, 1e-6), "{:?}", r.rgb);
        assert_eq!(*h, PixelHistory::default());
    }
    // ε_u = 0: the same pixels sample (n_min on a cold start).
    let s0 = SssPassSettings { split: Some(Split { gamma: None, eps_u: 0.0 }), ..s };
    let (r, _) = step(&tiny, &s0, 0, &[]);
    assert!(r.iter().all(|r| r.count == s.spvg.n_min));
}

/// SPVG tracks the distant term only (Sec. 5.3.1's last paragraph): AS's μ after a cold start
/// is the encoded luminance of γ·L_s, not of the whole L_o.
#[test]
fn spvg_tracks_the_distant_term() {
    let b = [0.8, 0.8, 0.8];
    let frame = flat(b, [2.0; 3]);
    let s = SssPassSettings::default();
    let (r, h) = step(&frame, &s, 0, &[]);
    let gamma = 1.0 - split::cdf(R0_PX, 2.0);
    let expected = encode(0.8 * gamma, s.monitor_gamma);
    for (r, h) in r.iter().zip(&h) {
        assert!(close(r.rgb[1], 0.8, 1e-5));
        assert!(close(h.spvg.mu, expected, 1e-5), "mu {} expected {expected}", h.spvg.mu);
    }
}

/// Eq. 7.1 on a depth edge: the left half (near, w = 1) is lit 0.2, the right half 1.0. With a
/// far right half (ΔD of thousands of pixels) R(r') is zero there and the renormalised sum is
/// the near side's 0.2 at the edge; at one depth the bright side bleeds in. Texels off the mask
/// (w = 0) with any irradiance weigh nothing: the result stays 0.2 (renormalised, not darkened).
#[test]
fn bilateral_weights_stop_at_a_depth_edge() {
    let edge = |right_w: f32, focal_px: f32| SssFrame {
        width: W,
        height: H,
        irradiance: (0..W * H)
            .map(|i| if i % W < W / 2 { [0.2, 0.2, 0.2, 1.0] } else { [1.0, 1.0, 1.0, right_w] })
            .collect(),
        d_px: [2.0, 1.5, 1.0],
        focal_px,
        motion: Vec::new(),
    };
    let s = SssPassSettings { variant: SssVariant::Fixed { count: 64 }, ..Default::default() };
    let (x, y) = (W / 2 - 1, H / 2);
    let far = scatter(&edge(1e-4, 500.0), &s, None, 1, x, y, 64);
    for c in 0..3 {
        assert!(close(far.rgb[c], 0.2, 1e-5), "far edge {c}: {:?}", far.rgb);
    }
    let same_depth = scatter(&edge(1.0, 500.0), &s, None, 1, x, y, 64);
    assert!(same_depth.rgb[0] > 0.25, "one depth: the bright side bleeds in: {:?}", same_depth.rgb);
    let off_mask = scatter(&edge(0.0, 500.0), &s, None, 1, x, y, 64);
    for c in 0..3 {
        assert!(close(off_mask.rgb[c], 0.2, 1e-5), "off mask {c}: {:?}", off_mask.rgb);
    }
}

/// γ and ε_u outside [0, 1] are refused by the settings' check.
#[test]
fn split_settings_outside_the_unit_interval_are_refused() {
    for bad in [
        Split { gamma: Some(1.5), eps_u: 0.01 },
        Split { gamma: Some(-0.1), eps_u: 0.01 },
        Split { gamma: None, eps_u: 2.0 },
        Split { gamma: None, eps_u: f32::NAN },
    ] {
        let s = SssPassSettings { split: Some(bad), ..Default::default() };
        assert!(s.validate().is_err(), "{bad:?}");
    }
    assert!(SssPassSettings::default().validate().is_ok());
}

/// Eq. 5.20 (`DistantCount::GammaScaled`) on hand-made inputs: m̂ = n̂·γ, rounded to the
/// nearest count and at least 1 (the pixels under ε_u are left out before it, see below);
/// `Estimated` (Algorithm 3) takes SPVG's count as m itself.
#[test]
fn eq_5_20_scales_spvgs_count_by_gamma() {
    use sss::DistantCount::{Estimated, GammaScaled};
    // (n̂, γ, m): n̂·γ = 32, 2, 33.68, 3.7, 1.3, 19.8, 64, and 0.4 (one sample).
    for (n_hat, gamma, m) in [
        (64, 0.5, 32),
        (8, 0.25, 2),
        (40, 0.842, 34),
        (10, 0.37, 4),
        (13, 0.1, 1),
        (20, 0.99, 20),
        (64, 1.0, 64),
        (8, 0.05, 1),
    ] {
        assert_eq!(split::distant_count(GammaScaled, n_hat, gamma), m, "n̂ {n_hat} γ {gamma}");
        assert_eq!(split::distant_count(Estimated, n_hat, gamma), n_hat, "n̂ {n_hat} γ {gamma}");
    }
}

/// The CPU pass takes eq. 5.20's count where the settings say `GammaScaled`: with SPVG's count
/// pinned (n_min = n_max = 40, so n̂ = 40 on every frame) every pixel of a flat frame takes
/// m = round(40·γ) distant samples on each of three frames, γ = 1 − cdf(r0) of Table 5.1 from
/// the pixel's d (computed here in f64 from eq. 5.3) or a constant γ; the history keeps n̂, not
/// m. `Estimated` takes 40 on the same frames. Where γ < ε_u no sample is taken (eq. 5.20's
/// first case) under either rule.
#[test]
fn the_pass_takes_eq_5_20s_count_when_gamma_scaled() {
    let spvg = sss::SpvgSettings { n_min: 40, n_max: 40, ..Default::default() };
    let burley_gamma = |d: f64| {
        let r0 = std::f64::consts::FRAC_1_SQRT_2;
        0.25 * (-r0 / d).exp() + 0.75 * (-r0 / (3.0 * d)).exp()
    };
    let cases = [
        (0.5, None, burley_gamma(0.5)),
        (2.0, None, burley_gamma(2.0)),
        (6.0, None, burley_gamma(6.0)),
        (2.0, Some(0.3), 0.3),
        (2.0, Some(0.55), 0.55),
    ];
    for (d, constant, gamma) in cases {
        let frame = flat([0.6, 0.5, 0.4], [d as f32; 3]);
        let m = (40.0 * gamma).round() as u32;
        for (rule, expected) in [(sss::DistantCount::GammaScaled, m), (Default::default(), 40)] {
            let s = SssPassSettings {
                spvg,
                split: Some(Split { gamma: constant, eps_u: 0.01 }),
                distant_count: rule,
                ..Default::default()
            };
            let mut history = Vec::new();
            for frame_index in 0..3 {
                let (r, h) = step(&frame, &s, frame_index, &history);
                for (r, h) in r.iter().zip(&h) {
                    assert_eq!(r.count, expected, "d {d} γ {gamma} {rule:?} frame {frame_index}");
                    assert_eq!(h.spvg.nbar, 40.0, "d {d} {rule:?}: the history keeps n̂");
                }
                history = h;
            }
        }
    }
    // γ under ε_u: no distant samples, eq. 5.20's m̂ = 0, not max(1, ·).
    let tiny = flat([0.5; 3], [0.05; 3]);
    let s = SssPassSettings {
        spvg,
        distant_count: sss::DistantCount::GammaScaled,
        ..Default::default()
    };
    let (r, _) = step(&tiny, &s, 0, &[]);
    assert!(r.iter().all(|r| r.count == 0), "{:?}", r[0]);
}
