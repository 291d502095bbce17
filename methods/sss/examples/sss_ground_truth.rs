//! The thesis's PSNR comparison against two references (support::ground_truth): each variant of the
//! pass on a flat half-space of albedo 0.99 under a diagonal shadow edge with a falloff, PSNR of
//! luminance against the screen-space pass itself at 4096 x 8 samples (the thesis's kind of
//! reference: the diffusion model converged) and against the random walk's exitance (the
//! transport the model approximates). The gap between the two columns is the diffusion
//! model's own error, beside each variant's noise. d = ℓ_d/s(A) with the walk's A (Θ3), 2 px.
//!
//! cargo run -p sss --example sss_ground_truth -- [WIDTH HEIGHT WALKS]

#[path = "../tests/support/mod.rs"]
mod support;

use sss::profile::scaling_from_dmfp;
use sss::screen_pass::step;
use sss::{PixelHistory, PixelResult, Prefilter, SssFrame, SssPassSettings, SssVariant};
use support::evaluation::psnr;
use support::ground_truth::WalkOffsets;
use support::random_walk::Medium;

fn main() {
    let args: Vec<u64> =
        std::env::args().skip(1).map(|a| a.parse().expect("a whole number")).collect();
    let (w, h, walks) = match args[..] {
        [w, h, n] => (w as u32, h as u32, n),
        [] => (64, 36, 40_000),
        _ => panic!("usage: sss_ground_truth [WIDTH HEIGHT WALKS]"),
    };
    let medium = Medium::unit(0.99);
    let ld = medium.diffuse_mean_free_path();
    let probe = WalkOffsets::trace(&medium, 100_000, 2, 1.0);
    let d = ld / scaling_from_dmfp(probe.albedo);
    let irradiance = (0..w * h)
        .map(|i| {
            let (x, y) = ((i % w) as f32, (i / w) as f32);
            let lit = if x + 0.6 * y < 0.55 * w as f32 { 1.0 } else { 0.1 };
            let e = lit * (1.0 - 0.4 * y / h as f32);
            [e, e, e, 1.0]
        })
        .collect();
    let frame =
        SssFrame { width: w, height: h, irradiance, d_px: [2.0; 3], focal_px: 0.0, motion: vec![] };
    let truth: Vec<[f32; 3]> = WalkOffsets::trace(&medium, walks, 1, d / 2.0)
        .truth(&frame)
        .iter()
        .map(|t| t.map(|v| v as f32))
        .collect();
    let plain = SssPassSettings { fast_inverse: false, split: None, ..Default::default() };
    let converged: Vec<[f32; 3]> = {
        let s = SssPassSettings { variant: SssVariant::Fixed { count: 4096 }, ..plain };
        let mut sum = vec![[0.0f32; 3]; (w * h) as usize];
        for f in 0..8 {
            for (a, r) in sum.iter_mut().zip(step(&frame, &s, f, &[]).0) {
                for (a, v) in a.iter_mut().zip(r.rgb) {
                    *a += v / 8.0;
                }
            }
        }
        sum
    };
    let peak = truth.iter().map(|t| t[0] as f64).fold(0.0, f64::max);
    let as_is = |r: &[[f32; 3]]| -> Vec<PixelResult> {
        r.iter().map(|c| PixelResult { rgb: *c, count: 0 }).collect()
    };
    println!(
        "{w}x{h}, {walks} walks (A = {:.4}, ℓ_d = {ld:.3} mfp, d = {d:.3} mfp = 2 px), peak {peak:.3}\n",
        probe.albedo
    );
    println!("| variant | mean spp (frames 20-29) | PSNR vs pass 4096x8 | PSNR vs random walk |");
    println!("|---|---|---|---|");
    println!(
        "| pass 4096x8 | 4096 | inf | {:.2} |",
        psnr(&as_is(&converged), &truth, &frame, peak)
    );
    let variants = [
        ("fixed 8", SssPassSettings { variant: SssVariant::Fixed { count: 8 }, ..plain }),
        ("fixed 64", SssPassSettings { variant: SssVariant::Fixed { count: 64 }, ..plain }),
        ("AS (split, fast inverse)", SssPassSettings::default()),
        (
            "AS+OCV (split, fast inverse)",
            SssPassSettings { variant: SssVariant::OnlineCv, ..Default::default() },
        ),
        (
            "AFIS a = 1/16",
            SssPassSettings { prefilter: Some(Prefilter::default()), ..Default::default() },
        ),
        ("separable 25", SssPassSettings { variant: SssVariant::Separable { taps: 25 }, ..plain }),
    ];
    for (name, s) in variants {
        let mut history: Vec<PixelHistory> = vec![];
        let (mut last, mut counts) = (vec![], 0.0);
        for f in 0..30 {
            let (r, next) = step(&frame, &s, f, &history);
            if f >= 20 {
                counts += r.iter().map(|r| r.count as f64).sum::<f64>() / r.len() as f64 / 10.0;
            }
            (last, history) = (r, next);
        }
        println!(
            "| {name} | {counts:.2} | {:.2} | {:.2} |",
            psnr(&last, &converged, &frame, peak),
            psnr(&last, &truth, &frame, peak)
        );
    }
}
