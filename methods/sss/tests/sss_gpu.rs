//! The WGSL SSS pass (sss::gpu) against its CPU twin (sss::screen_pass) on a
//! tiny image: one step from the same varied histories per variant, then two frames with the
//! GPU's own ping-pong histories.

use render::gpu::Gpu;
use render::scene::SplitMix64;
use sss::gpu::SssPass;
use sss::prefilter::MipChain;
use sss::screen_pass::step;
use sss::{
    DistantCount, EmCovariance, PixelHistory, PixelResult, Prefilter, Split, SpvgHistory,
    SpvgSettings, SssFrame, SssPassSettings, SssVariant,
};

const W: u32 = 20;
const H: u32 = 12;

/// A lit patch with a shadow edge and a smooth falloff, and a non-SSS block in one corner.
fn frame() -> SssFrame {
    let irradiance = (0..W * H)
        .map(|i| {
            let (x, y) = ((i % W) as f32, (i / W) as f32);
            let lit = if x + 0.5 * y < 11.0 { 1.0 } else { 0.15 };
            let fall = 1.0 - 0.03 * y;
            // w: pixels per unit of d, varying as depth would; 0 off the SSS mask.
            // The last row's tiny w puts γ under ε_u (eq. 5.20: no distant samples).
            let scale = if x >= 16.0 && y < 4.0 {
                0.0
            } else if y == 11.0 {
                0.02
            } else {
                0.8 + 0.03 * x
            };
            [lit * fall, 0.8 * lit * fall, 0.6 * lit, scale]
        })
        .collect();
    // focal_px: depth = focal/w varies with x, so eq. 7.1's depth term is exercised.
    SssFrame {
        width: W,
        height: H,
        irradiance,
        d_px: [1.5, 0.8, 0.4],
        focal_px: 6.0,
        motion: Vec::new(),
    }
}

/// The unrounded n̂ of eq. 4.9 in f64, to keep away from rounding ties in the test data.
fn count_f64(h: &SpvgHistory, s: &SpvgSettings) -> f64 {
    let k = 2.0 / s.alpha0 as f64 - 1.0;
    let ratio = h.sigma2 as f64 / s.sigma0_sq as f64;
    s.kappa as f64 * (ratio - 1.0) * h.nbar as f64 * (k - 1.0) + ratio * h.nbar as f64
}

/// Random histories: a quarter invalid (disoccluded), the rest with counts spread over [8, 64];
/// the w they were written at unknown (0), near the frame's (0.8-1.37) or far from it.
fn histories(s: &SpvgSettings) -> Vec<PixelHistory> {
    let mut rng = SplitMix64::new(7);
    (0..W * H)
        .map(|_| {
            loop {
                let valid = rng.next_f32() > 0.25;
                let spvg = SpvgHistory {
                    mu: rng.range(0.0, 1.2),
                    sigma2: s.sigma0_sq * rng.range(0.3, 3.0),
                    nbar: rng.range(8.0, 40.0),
                    valid,
                };
                let cv = EmCovariance {
                    mean_f: rng.range(0.1, 1.0),
                    mean_g: rng.range(0.1, 1.0),
                    cov_fg: rng.range(-0.01, 0.02),
                    var_g: rng.range(0.0, 0.02),
                };
                let w = [0.0, rng.range(0.8, 1.4), 2.5][(rng.next_f32() * 3.0) as usize % 3];
                let frac = count_f64(&spvg, s).fract();
                if !valid || (frac - 0.5).abs() > 1e-3 {
                    break PixelHistory { spvg, cv, w };
                }
            }
        })
        .collect()
}

fn close(a: f32, b: f32, rel: f32, abs: f32) -> bool {
    (a - b).abs() <= rel * a.abs().max(b.abs()) + abs
}

fn compare(
    what: &str,
    gpu: (&[PixelResult], &[PixelHistory]),
    cpu: (&[PixelResult], &[PixelHistory]),
) {
    for (i, ((rg, hg), (rc, hc))) in
        gpu.0.iter().zip(gpu.1).zip(cpu.0.iter().zip(cpu.1)).enumerate()
    {
        assert_eq!(rg.count, rc.count, "{what} pixel {i}: count");
        for c in 0..3 {
            // f32 transcendental functions differ by a few ulps between the two sides.
            assert!(
                close(rg.rgb[c], rc.rgb[c], 1e-4, 1e-6),
                "{what} pixel {i} channel {c}: gpu {:?} cpu {:?}",
                rg.rgb,
                rc.rgb
            );
        }
        let (a, b) = (hg.spvg, hc.spvg);
        assert_eq!(a.valid, b.valid, "{what} pixel {i}");
        assert!(close(hg.w, hc.w, 1e-5, 1e-6), "{what} pixel {i}: w {} vs {}", hg.w, hc.w);
        assert!(
            close(a.mu, b.mu, 1e-4, 1e-6) && close(a.nbar, b.nbar, 1e-5, 0.0),
            "{what} pixel {i}: {a:?} vs {b:?}"
        );
        assert!(close(a.sigma2, b.sigma2, 1e-3, 1e-9), "{what} pixel {i}: {a:?} vs {b:?}");
        let (a, b) = (hg.cv, hc.cv);
        for (x, y) in
            [(a.mean_f, b.mean_f), (a.mean_g, b.mean_g), (a.cov_fg, b.cov_fg), (a.var_g, b.var_g)]
        {
            assert!(close(x, y, 1e-3, 1e-9), "{what} pixel {i}: cv {a:?} vs {b:?}");
        }
    }
}

/// Motion for every pixel: whole and fractional shifts up to 3 px, some off screen.
fn motion() -> Vec<[f32; 2]> {
    let mut rng = SplitMix64::new(5);
    (0..W * H).map(|_| [rng.range(-3.0, 3.0), rng.range(-3.0, 3.0)]).collect()
}

#[test]
fn gpu_pass_matches_the_cpu_reference() {
    let gpu = Gpu::new().expect("a wgpu adapter (lavapipe on CI)");
    for motion in [Vec::new(), motion()] {
        gpu_pass_matches_with_motion(&gpu, SssFrame { motion, ..frame() });
    }
}

fn gpu_pass_matches_with_motion(gpu: &Gpu, frame: SssFrame) {
    let mut pass = SssPass::new(gpu, W, H).unwrap();
    let thesis = Some(Split::default());
    let (estimated, eq520) = (DistantCount::Estimated, DistantCount::GammaScaled);
    let variants = [
        (SssVariant::Fixed { count: 64 }, false, thesis, 2.2, estimated),
        (SssVariant::Adaptive, true, thesis, 2.2, estimated),
        (SssVariant::OnlineCv, true, thesis, 2.2, estimated),
        (SssVariant::ConstantCv, true, thesis, 2.2, estimated),
        (SssVariant::Adaptive, false, thesis, 2.2, estimated),
        (SssVariant::Adaptive, true, None, 1.0, estimated),
        (SssVariant::OnlineCv, true, Some(Split { gamma: Some(0.4), eps_u: 0.3 }), 1.0, estimated),
        // Eq. 5.20's m = n̂·γ: Burley's γ per pixel and a constant one.
        (SssVariant::Adaptive, true, thesis, 2.2, eq520),
        (SssVariant::ConstantCv, true, Some(Split { gamma: Some(0.4), eps_u: 0.01 }), 2.2, eq520),
    ];
    for (variant, fast_inverse, split, monitor_gamma, distant_count) in variants {
        let settings = SssPassSettings {
            variant,
            fast_inverse,
            seed: 3,
            split,
            monitor_gamma,
            distant_count,
            ..Default::default()
        };
        let what = format!(
            "{variant:?} fast {fast_inverse} {split:?} gamma {monitor_gamma} {distant_count:?} moving {}",
            !frame.motion.is_empty()
        );
        let start = histories(&settings.spvg);
        pass.set_history(gpu, &start);
        pass.dispatch(gpu, &frame, &settings, 5).unwrap();
        let (results, next) = (pass.results(gpu).unwrap(), pass.history(gpu).unwrap());
        let (cpu_results, cpu_next) = step(&frame, &settings, 5, &start);
        compare(&what, (&results, &next), (&cpu_results, &cpu_next));
        // The variants do differ: counts are not all one value outside Fixed.
        if !matches!(variant, SssVariant::Fixed { .. }) {
            let counts: std::collections::BTreeSet<u32> =
                results.iter().map(|r| r.count).filter(|&c| c > 0).collect();
            assert!(counts.len() > 5, "{what}: {counts:?}");
            if distant_count == estimated {
                assert!(counts.contains(&8), "{what}: {counts:?}");
            }
        }
        // Eq. 5.20 on the GPU: with a constant γ each pixel takes max(1, round(n̂·γ)) of the
        // n̂ that Algorithm 3 would take from the same history.
        if let (DistantCount::GammaScaled, Some(Split { gamma: Some(g), .. })) =
            (distant_count, split)
        {
            let algorithm3 = SssPassSettings { distant_count: estimated, ..settings };
            let (n_hat, _) = step(&frame, &algorithm3, 5, &start);
            let mut scaled = 0;
            for (i, (r, n)) in results.iter().zip(&n_hat).enumerate() {
                if n.count > 0 {
                    let m = ((n.count as f32 * g).round() as u32).max(1);
                    assert_eq!(r.count, m, "{what} pixel {i}: n̂ {}", n.count);
                    scaled += (m != n.count) as usize;
                }
            }
            assert!(scaled > 100, "{what}: {scaled} pixels scaled");
        }
        // Second frame from the GPU's own (flipped) history.
        pass.dispatch(gpu, &frame, &settings, 6).unwrap();
        let (results2, next2) = (pass.results(gpu).unwrap(), pass.history(gpu).unwrap());
        let (cpu2, cpu_next2) = step(&frame, &settings, 6, &next);
        let ties = next
            .iter()
            .filter(|h| {
                h.spvg.valid
                    && (count_f64(&h.spvg, &settings.spvg).clamp(8.0, 64.0).fract() - 0.5).abs()
                        < 1e-3
            })
            .count();
        if ties == 0 {
            compare(&format!("{what} frame 2"), (&results2, &next2), (&cpu2, &cpu_next2));
        }
    }
}

/// AFIS: the prefiltering pass's MIP chain against `MipChain::build`, level by level, and the
/// prefiltered pass against its CPU twin; prefiltering changes the image (the path is taken).
#[test]
fn gpu_prefiltered_pass_matches_the_cpu_reference() {
    let gpu = Gpu::new().expect("a wgpu adapter (lavapipe on CI)");
    let frame = frame();
    let mut pass = SssPass::new(&gpu, W, H).unwrap();
    for (variant, prefilter) in [
        (SssVariant::Adaptive, Prefilter::default()),
        (SssVariant::Fixed { count: 24 }, Prefilter { a: 1.0, levels: 3 }),
    ] {
        let plain = SssPassSettings { variant, seed: 3, ..Default::default() };
        let settings = SssPassSettings { prefilter: Some(prefilter), ..plain };
        let start = histories(&settings.spvg);
        pass.set_history(&gpu, &start);
        pass.dispatch(&gpu, &frame, &settings, 5).unwrap();
        let what = format!("{variant:?} {prefilter:?}");
        let chain = MipChain::build(W, H, &frame.irradiance, prefilter.levels);
        let mips = pass.mips(&gpu, prefilter.levels).unwrap();
        assert_eq!(mips.len(), chain.levels.len());
        for (k, (g, c)) in mips.iter().zip(&chain.levels).enumerate() {
            assert_eq!(g.len(), c.len(), "{what} level {k}");
            for (i, (a, b)) in g.iter().zip(c).enumerate() {
                assert!(
                    (0..4).all(|j| close(a[j], b[j], 1e-6, 1e-7)),
                    "{what} level {k} texel {i}: gpu {a:?} cpu {b:?}"
                );
            }
        }
        let (results, next) = (pass.results(&gpu).unwrap(), pass.history(&gpu).unwrap());
        let (cpu_results, cpu_next) = step(&frame, &settings, 5, &start);
        compare(&what, (&results, &next), (&cpu_results, &cpu_next));
        let (unfiltered, _) = step(&frame, &plain, 5, &start);
        let changed = results
            .iter()
            .zip(&unfiltered)
            .filter(|(a, b)| (a.rgb[0] - b.rgb[0]).abs() > 1e-4)
            .count();
        assert!(changed > 10, "{what}: prefiltering changed {changed} pixels");
    }
    // Separable has no samples to prefilter.
    let bad = SssPassSettings {
        variant: SssVariant::Separable { taps: 5 },
        prefilter: Some(Prefilter::default()),
        ..Default::default()
    };
    assert!(pass.dispatch(&gpu, &frame, &bad, 0).unwrap_err().to_string().contains("Separable"));
}

#[test]
fn bad_sizes_and_counts_are_refused() {
    let gpu = Gpu::new().expect("a wgpu adapter (lavapipe on CI)");
    assert!(SssPass::new(&gpu, 0, 4).is_err());
    let mut pass = SssPass::new(&gpu, W, H).unwrap();
    let e = pass
        .dispatch(
            &gpu,
            &frame(),
            &SssPassSettings { variant: SssVariant::Fixed { count: 5000 }, ..Default::default() },
            0,
        )
        .unwrap_err();
    assert!(e.to_string().contains("5000"), "{e}");
    let small = SssFrame {
        width: 4,
        height: 4,
        irradiance: vec![[0.0; 4]; 16],
        d_px: [1.0; 3],
        focal_px: 0.0,
        motion: Vec::new(),
    };
    assert!(
        pass.dispatch(&gpu, &small, &SssPassSettings::default(), 0)
            .unwrap_err()
            .to_string()
            .contains("4x4")
    );
}
