//! Reprojection of SPVG's history (eqs. 4.11-4.12 with motion): a translated view reads the
//! shifted history; a disocclusion (no SSS history at the reprojected texel, off screen, or a
//! depth that disagrees) resets it. CPU twin; the WGSL pass is checked against it in sss_gpu.

use render::scene::SplitMix64;
use sss::screen_pass::step;
use sss::spvg::{sample_count, state};
use sss::{PixelHistory, SpvgHistory, SssFrame, SssPassSettings};

const W: u32 = 24;
const H: u32 = 10;
const SHIFT: i32 = 3;
const SCALE: f32 = 0.9;

/// A smooth SSS patch, translated `dx` pixels to the right; w = SCALE everywhere.
fn frame(dx: i32, motion: Vec<[f32; 2]>) -> SssFrame {
    let irradiance = (0..W * H)
        .map(|i| {
            let (x, y) = ((i % W) as i32 - dx, (i / W) as f32);
            let v = 0.5 + 0.4 * (0.4 * x as f32).sin() * (0.3 * y).cos();
            [v, 0.8 * v, 0.6 * v, SCALE]
        })
        .collect();
    SssFrame { width: W, height: H, irradiance, d_px: [1.5, 0.8, 0.4], focal_px: 0.0, motion }
}

/// Valid histories whose counts differ from pixel to pixel (n̂ spread over [8, 64]).
fn histories(settings: &SssPassSettings) -> Vec<PixelHistory> {
    let mut rng = SplitMix64::new(11);
    (0..W * H)
        .map(|_| PixelHistory {
            spvg: SpvgHistory {
                mu: rng.range(0.2, 1.0),
                sigma2: settings.spvg.sigma0_sq * rng.range(0.3, 4.0),
                nbar: rng.range(8.0, 40.0),
                valid: true,
            },
            w: SCALE,
            ..Default::default()
        })
        .collect()
}

fn expected_count(h: &PixelHistory, settings: &SssPassSettings) -> u32 {
    sample_count(&state(&h.spvg, &settings.spvg), &settings.spvg)
}

#[test]
fn a_translated_view_reads_the_shifted_history() {
    let settings = SssPassSettings::default();
    let prev = histories(&settings);
    // The image moved SHIFT pixels right: each pixel was SHIFT pixels left last frame.
    let moving = frame(SHIFT, vec![[-SHIFT as f32, 0.0]; (W * H) as usize]);
    let (results, next) = step(&moving, &settings, 1, &prev);
    let mut differs = 0;
    for y in 0..H {
        for x in 0..W {
            let i = (y * W + x) as usize;
            if (x as i32) < SHIFT {
                // Off screen last frame: a cold start (α = 1, σ̂² = σ0², n̄ = n_min).
                assert_eq!(results[i].count, settings.spvg.n_min, "pixel ({x}, {y})");
                assert_eq!(next[i].spvg.sigma2, settings.spvg.sigma0_sq, "pixel ({x}, {y})");
                continue;
            }
            let from = &prev[i - SHIFT as usize];
            assert_eq!(results[i].count, expected_count(from, &settings), "pixel ({x}, {y})");
            // n̄ follows the shifted history: (1 − α0) n̄_prev + α0 n.
            let a = settings.spvg.alpha0;
            let nbar = (1.0 - a) * from.spvg.nbar + a * results[i].count as f32;
            assert!((next[i].spvg.nbar - nbar).abs() < 1e-4, "pixel ({x}, {y})");
            differs += (expected_count(&prev[i], &settings) != results[i].count) as u32;
        }
    }
    // The unshifted read would give other counts: the test sees the reprojection.
    assert!(differs > (W * H) / 4, "only {differs} pixels tell the shifted read apart");
    // No motion: the same pixel's history, as before reprojection.
    let (still, _) = step(&frame(0, Vec::new()), &settings, 1, &prev);
    for (i, r) in still.iter().enumerate() {
        assert_eq!(r.count, expected_count(&prev[i], &settings), "still pixel {i}");
    }
}

#[test]
fn a_disocclusion_resets_the_history() {
    let settings = SssPassSettings::default();
    let mut prev = histories(&settings);
    // Last frame: columns 0-5 were another surface (no SSS history), columns 6-11 at 1.5x
    // this frame's w (depth 1/1.5 of this one: another surface in front), 12-17 at w within
    // the tolerance, 18-23 unchanged.
    for y in 0..H {
        for x in 0..W {
            let h = &mut prev[(y * W + x) as usize];
            match x {
                0..=5 => *h = PixelHistory::default(),
                6..=11 => h.w = 1.5 * SCALE,
                12..=17 => h.w = SCALE * (1.0 + 0.5 * settings.depth_tolerance),
                _ => {}
            }
        }
    }
    let still = frame(0, vec![[0.0, 0.0]; (W * H) as usize]);
    let (results, next) = step(&still, &settings, 2, &prev);
    for y in 0..H {
        for x in 0..W {
            let i = (y * W + x) as usize;
            if x < 12 {
                // M' = 1, σ̂² = σ0² (eqs. 4.11-4.12): n = n_min, H restarts from this frame.
                assert_eq!(results[i].count, settings.spvg.n_min, "pixel ({x}, {y})");
                assert_eq!(next[i].spvg.sigma2, settings.spvg.sigma0_sq, "pixel ({x}, {y})");
                assert_eq!(next[i].spvg.nbar, settings.spvg.n_min as f32, "pixel ({x}, {y})");
            } else {
                assert_eq!(results[i].count, expected_count(&prev[i], &settings), "({x}, {y})");
                assert_ne!(next[i].spvg.sigma2, settings.spvg.sigma0_sq, "pixel ({x}, {y})");
            }
        }
    }
    // Kept pixels do not all take n_min (the reset is not everywhere).
    assert!(results.iter().skip(12).any(|r| r.count > settings.spvg.n_min));
}
