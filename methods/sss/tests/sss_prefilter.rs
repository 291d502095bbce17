//! AFIS's prefiltered MIP chain (sss::prefilter, thesis Sec. 5.2) on the CPU: a 2x2 box
//! chain reproduces a linear irradiance exactly wherever its footprint stays inside the image, so
//! the prefiltered pass equals the unfiltered one there (a wrong texel centre, level size or
//! level offset breaks this); on a step edge prefiltering blurs, so it must differ there.

use sss::screen_pass::{mip_chain, scatter};
use sss::{Prefilter, SssFrame, SssPassSettings, SssVariant};

const W: u32 = 96;
const H: u32 = 80;

fn frame(f: impl Fn(f32, f32) -> f32) -> SssFrame {
    let irradiance = (0..W * H)
        .map(|i| {
            let (x, y) = ((i % W) as f32 + 0.5, (i / W) as f32 + 0.5);
            let v = f(x, y);
            [v, 0.5 * v, 0.25 * v, 1.0]
        })
        .collect();
    // One d for all channels: each sample's weight is 1, the estimate a plain mean of fetches.
    SssFrame { width: W, height: H, irradiance, d_px: [0.6; 3], focal_px: 0.0, motion: Vec::new() }
}

#[test]
fn prefiltering_is_exact_on_a_linear_irradiance() {
    let ramp = frame(|x, y| 0.2 + 0.01 * x + 0.004 * y);
    let plain =
        SssPassSettings { variant: SssVariant::Fixed { count: 32 }, seed: 5, ..Default::default() };
    let afis = SssPassSettings { prefilter: Some(Prefilter { a: 1.0 / 16.0, levels: 5 }), ..plain };
    let chain = mip_chain(&ramp, &afis).expect("a chain");
    assert_eq!(chain.levels.len(), 5);
    // The top level's texel (1, 1) is the mean of a 16x16 block: the ramp at its centre.
    let top = chain.levels[4][(6 + 1) as usize];
    let centre = 0.2 + 0.01 * 24.0 + 0.004 * 24.0;
    assert!((top[0] - centre).abs() < 1e-5 && top[3] == 1.0, "{top:?} vs {centre}");
    let mut largest_level_gap = 0.0f32;
    for (x, y) in [(48, 40), (40, 36), (55, 45)] {
        let a = scatter(&ramp, &plain, None, 3, x, y, 32).rgb;
        let b = scatter(&ramp, &afis, Some(&chain), 3, x, y, 32).rgb;
        for c in 0..3 {
            assert!(
                (a[c] - b[c]).abs() <= 2e-5 * a[c].abs(),
                "pixel ({x}, {y}) channel {c}: plain {a:?} afis {b:?}"
            );
        }
        largest_level_gap = largest_level_gap.max((a[0] - b[0]).abs());
    }
    // The samples did read levels above 0 (else the comparison proves nothing): at n = 32 and
    // d = 0.6 px a tail sample stands for far more than a/4 texels.
    let tail = sss::prefilter::level(8.0, sss::sampling::radial_pdf(8.0, 0.6), 32, 1.0 / 16.0, 5);
    assert!(tail > 2.0, "tail level {tail}");
    eprintln!("largest plain/afis gap on the ramp: {largest_level_gap}");
}

#[test]
fn prefiltering_blurs_an_edge() {
    let edge = frame(|x, _| if x < 48.0 { 1.0 } else { 0.1 });
    let plain =
        SssPassSettings { variant: SssVariant::Fixed { count: 32 }, seed: 5, ..Default::default() };
    let afis = SssPassSettings { prefilter: Some(Prefilter::default()), ..plain };
    let chain = mip_chain(&edge, &afis).expect("a chain");
    let a = scatter(&edge, &plain, None, 3, 46, 40, 32).rgb;
    let b = scatter(&edge, &afis, Some(&chain), 3, 46, 40, 32).rgb;
    assert!((a[0] - b[0]).abs() > 1e-3, "plain {a:?} afis {b:?}");
}
