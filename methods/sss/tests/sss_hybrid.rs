//! The hybrid pass (Sec. 5.3.2): its decision rule against a reference that places the separable
//! taps in pixels as the 1-D passes do; the CPU twin's P1-P4 against AFIS alone and separable
//! alone, and without dim borders on a flat irradiance; the WGSL passes against the CPU twin,
//! with both techniques taken where the rule expects them.

use render::gpu::Gpu;
use sss::hybrid::{self, Hybrid, TILE, Technique};
use sss::screen_pass::step;
use sss::{PixelHistory, Prefilter, SssFrame, SssPassSettings, SssVariant};

const W: u32 = 24;
const H: u32 = 16;
const D: [f32; 3] = [1.5, 0.8, 0.4];

/// w (pixels per unit of d) per pixel: tile column 0 small (separable), column 1 small but for
/// one pixel, column 2 large (AFIS); the lower-right tile off the SSS mask but for nothing.
fn w_at(x: u32, y: u32) -> f32 {
    match (x / TILE, y / TILE) {
        (2, 1) => 0.0,
        (0, _) => 0.3 + 0.01 * y as f32,
        (1, _) if (x, y) == (13, 2) => 0.9,
        (1, _) => 0.35,
        _ => 0.8 + 0.02 * x as f32,
    }
}

fn frame(irradiance: impl Fn(u32, u32) -> [f32; 3]) -> SssFrame {
    let irradiance = (0..W * H)
        .map(|i| {
            let (x, y) = (i % W, i / W);
            let [r, g, b] = irradiance(x, y);
            [r, g, b, w_at(x, y)]
        })
        .collect();
    SssFrame { width: W, height: H, irradiance, d_px: D, focal_px: 6.0, motion: Vec::new() }
}

/// A shadow edge across the tiles and a smooth falloff.
fn lit(x: u32, y: u32) -> [f32; 3] {
    let l = if x as f32 + 0.7 * y as f32 > 14.0 { 1.0 } else { 0.15 };
    let f = 1.0 - 0.02 * y as f32;
    [l * f, 0.8 * l * f, 0.6 * l]
}

fn settings(hybrid: Hybrid) -> SssPassSettings {
    SssPassSettings {
        variant: SssVariant::Adaptive,
        prefilter: Some(Prefilter::default()),
        hybrid: Some(hybrid),
        seed: 3,
        ..Default::default()
    }
}

/// The rule by its reason: at each SSS pixel, the separable pass's tap positions in pixels
/// (the kernel's offsets times the sampled d times w, as the 1-D passes place them) and their
/// widest gap; a tile is AFIS where some pixel's widest gap exceeds max_gap_px.
fn reference_rule(frame: &SssFrame, h: &Hybrid) -> Vec<Technique> {
    let kernel = sss::separable::kernel(h.taps, frame.d_px).unwrap();
    let tx = frame.width.div_ceil(TILE);
    let mut out = vec![Technique::Separable; (tx * frame.height.div_ceil(TILE)) as usize];
    for y in 0..frame.height {
        for x in 0..frame.width {
            let w = frame.irradiance[(y * frame.width + x) as usize][3];
            if w <= 0.0 {
                continue;
            }
            let pos: Vec<f64> =
                kernel.iter().map(|k| k[0] as f64 * (frame.d_sample() * w) as f64).collect();
            let widest = pos.windows(2).map(|p| p[1] - p[0]).fold(0.0, f64::max);
            // A relative margin for the f32 path the pass takes (the frame keeps clear of it).
            if widest > h.max_gap_px as f64 * (1.0 - 1e-5) {
                out[((y / TILE) * tx + x / TILE) as usize] = Technique::Afis;
            }
        }
    }
    out
}

#[test]
fn the_decision_rule_matches_the_tap_gap_reference() {
    let f = frame(lit);
    for h in [
        Hybrid::default(),
        Hybrid { taps: 9, max_gap_px: 1.0 },
        Hybrid { taps: 25, max_gap_px: 0.5 },
        Hybrid { taps: 25, max_gap_px: 3.0 },
    ] {
        let got = hybrid::tile_techniques(&f, &h);
        assert_eq!(got, reference_rule(&f, &h), "{h:?}");
    }
    // The frame's intent under the defaults: column 0 separable, column 1 AFIS by one pixel,
    // column 2 AFIS, the tile without SSS separable.
    use Technique::{Afis, Separable};
    assert_eq!(
        hybrid::tile_techniques(&f, &Hybrid::default()),
        vec![Separable, Afis, Afis, Separable, Separable, Separable]
    );
    // Bad settings are refused with what was expected.
    for bad in [Hybrid { taps: 4, max_gap_px: 1.0 }, Hybrid { taps: 25, max_gap_px: 0.0 }] {
        let e = settings(bad).validate().unwrap_err();
        assert!(e.contains("hybrid"), "{e}");
    }
    let no_prefilter = SssPassSettings { prefilter: None, ..settings(Hybrid::default()) };
    assert!(no_prefilter.validate().unwrap_err().contains("prefilter"));
    let separable = SssPassSettings {
        variant: SssVariant::Separable { taps: 25 },
        ..settings(Hybrid::default())
    };
    assert!(separable.validate().unwrap_err().contains("Separable"));
}

#[test]
fn the_hybrid_is_afis_and_separable_where_each_is_chosen() {
    let f = frame(lit);
    let h = Hybrid::default();
    let s = settings(h);
    let tiles = hybrid::tile_techniques(&f, &h);
    let (hyb, hist) = step(&f, &s, 4, &[]);
    let (afis, afis_hist) = step(&f, &SssPassSettings { hybrid: None, ..s }, 4, &[]);
    let separable = SssPassSettings {
        variant: SssVariant::Separable { taps: h.taps },
        prefilter: None,
        hybrid: None,
        ..s
    };
    let (sep, _) = step(&f, &separable, 4, &[]);
    let mut interior = 0;
    for i in 0..(W * H) as usize {
        let (x, y) = (i as u32 % W, i as u32 / W);
        if hybrid::technique_at(&f, &tiles, i) == Technique::Afis {
            assert_eq!((hyb[i], hist[i]), (afis[i], afis_hist[i]), "AFIS pixel ({x}, {y})");
        } else {
            assert_eq!(hist[i], PixelHistory::default(), "separable pixel ({x}, {y}) history");
            // Away from the AFIS tiles (the vertical kernel's reach: ±8 d_s w px) the
            // separable tiles are the separable pass itself.
            let reach = (8.0 * f.d_sample() * w_at(x, y)).ceil() as u32 + 1;
            let near_afis = (y.saturating_sub(reach)..(y + reach + 1).min(H)).any(|yy| {
                hybrid::technique_at(&f, &tiles, (yy * W + x) as usize) == Technique::Afis
            });
            if !near_afis && x < 8 {
                assert_eq!(hyb[i], sep[i], "separable pixel ({x}, {y})");
                interior += 1;
            }
        }
    }
    assert!(interior > 50, "{interior} interior separable pixels compared");
    // Both techniques ran: Monte Carlo counts (8 at a cold start) and 2·taps.
    let counts: std::collections::BTreeSet<u32> = hyb.iter().map(|r| r.count).collect();
    assert!(counts.contains(&8) && counts.contains(&(2 * h.taps)), "{counts:?}");
}

/// A flat irradiance scatters to itself under both techniques; at the borders the vertical pass
/// reads P1's AFIS result as its first pass (the thesis's stand-in), so no border dims.
#[test]
fn a_flat_irradiance_has_no_dim_borders() {
    let f = frame(|_, _| [0.7, 0.5, 0.3]);
    let (hyb, _) = step(&f, &settings(Hybrid::default()), 2, &[]);
    for (i, r) in hyb.iter().enumerate() {
        for c in 0..3 {
            let b = f.irradiance[i][c];
            assert!((r.rgb[c] - b).abs() <= 2e-5 * b, "pixel {i} channel {c}: {:?}", r.rgb);
        }
    }
}

fn close(a: f32, b: f32) -> bool {
    (a - b).abs() <= 1e-4 * a.abs().max(b.abs()) + 1e-6
}

/// The WGSL passes (setup, prefilter, P1-P4) against the CPU twin over three frames from their
/// own histories, the tile buffer against the rule, and both techniques taken.
#[test]
fn gpu_hybrid_matches_the_cpu_twin_and_takes_both_paths() {
    let gpu = Gpu::new().expect("a wgpu adapter (lavapipe on CI)");
    let f = frame(lit);
    let mut pass = sss::gpu::SssPass::new(&gpu, W, H).unwrap();
    for h in [Hybrid::default(), Hybrid { taps: 41, max_gap_px: 1.0 }] {
        let s = settings(h);
        pass.set_history(&gpu, &[]);
        let mut cpu_history: Vec<PixelHistory> = Vec::new();
        for frame_index in 0..3 {
            pass.dispatch(&gpu, &f, &s, frame_index).unwrap();
            let tiles = pass.tiles(&gpu).unwrap();
            let expected: Vec<u32> =
                hybrid::tile_techniques(&f, &h).iter().map(|&t| t as u32).collect();
            assert_eq!(tiles, expected, "{h:?} frame {frame_index}");
            let (results, history) = (pass.results(&gpu).unwrap(), pass.history(&gpu).unwrap());
            let (cpu, next) = step(&f, &s, frame_index, &cpu_history);
            for (i, (g, c)) in results.iter().zip(&cpu).enumerate() {
                let what = format!("{h:?} frame {frame_index} pixel {i}");
                assert_eq!(g.count, c.count, "{what}");
                assert!((0..3).all(|k| close(g.rgb[k], c.rgb[k])), "{what}: {g:?} vs {c:?}");
                assert_eq!(history[i].spvg.valid, next[i].spvg.valid, "{what}");
                assert!(close(history[i].spvg.nbar, next[i].spvg.nbar), "{what}");
            }
            let afis = results.iter().filter(|r| (8..=64).contains(&r.count)).count();
            let sep = results.iter().filter(|r| r.count == 2 * h.taps).count();
            assert!(afis > 64 && sep > 64, "{h:?}: {afis} AFIS and {sep} separable pixels");
            cpu_history = next;
        }
    }
}
