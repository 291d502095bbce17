//! Table 7.3's analogue (thesis Sec. 7.4) for the WGSL SSS pass on the synthetic dynamic tests:
//! per test and variant (AS, AS+OCV, AS+CCV, fixed 64, AFIS (AS reading the prefiltered MIP
//! chain, a = 1/16, 6 levels), separable with 25 taps per 1-D pass, its "spp" the 50 fetches per
//! pixel) the mean spp, the pass's mean time per frame, PSNR against the same pass
//! at 2048 spp (analytic inverse) on every 6th frame after frame 10, and frame-to-frame SMAPE
//! (with the SMAPE of the pass at 128 fixed spp, the flicker of the lighting itself);
//! writes OUT/table.md and per-pixel mean-count images OUT/counts_TEST_VARIANT.pgm.
//!
//! cargo run --release -p render --example sss_table -- [WIDTH HEIGHT FRAMES OUT [A,A,...]]
//! (the last: eq. 5.12's a of each AFIS row, default the thesis's 0.0625).

use render::gpu::Gpu;
use sss::evaluation::Accumulator;
use sss::gpu::SssPass;
use sss::sampling::luminance;
use sss::synthetic::{DynamicTest, frame};
use sss::{Prefilter, SssSettings, SssVariant};
use std::fmt::Write;

const D_REL: [f32; 3] = [0.15, 0.08, 0.04];

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let arg = |i: usize, default: &str| args.get(i).cloned().unwrap_or_else(|| default.to_string());
    let (width, height, frames): (u32, u32, u32) =
        (arg(0, "320").parse()?, arg(1, "180").parse()?, arg(2, "60").parse()?);
    let out = std::path::PathBuf::from(arg(3, "sss_table"));
    let afis_a: Vec<f32> =
        arg(4, "0.0625").split(',').map(|a| a.parse()).collect::<Result<_, _>>()?;
    std::fs::create_dir_all(&out)?;
    let gpu = Gpu::new()?;
    let measured = |t: u32| t >= 10 && t % 6 == 4;
    let mut table = format!(
        "{width}x{height}, {frames} frames, adapter {}\n\n| test | variant | mean spp | ms/frame | PSNR dB | SMAPE | reference SMAPE |\n|---|---|---|---|---|---|---|\n",
        gpu.adapter.get_info().name
    );
    for test in [DynamicTest::Flash, DynamicTest::Toggle, DynamicTest::Boids] {
        // References, and the reference's own SMAPE between consecutive frames (the flicker the
        // lighting itself has).
        let mut reference_pass = SssPass::new(&gpu, width, height)?;
        let reference_settings = SssSettings {
            variant: SssVariant::Fixed { count: 2048 },
            fast_inverse: false,
            seed: 1000,
            ..Default::default()
        };
        let mut references = vec![None; frames as usize];
        let mut peak = 0.0f64;
        for t in (0..frames).filter(|&t| measured(t)) {
            let f = frame(test, width, height, t, D_REL);
            reference_pass.dispatch(&gpu, &f, &reference_settings, t)?;
            let r: Vec<[f32; 3]> = reference_pass.results(&gpu)?.iter().map(|p| p.rgb).collect();
            peak = r.iter().map(|c| luminance(*c) as f64).fold(peak, f64::max);
            references[t as usize] = Some(r);
        }
        let mut ref_smape = Accumulator::default();
        for t in 0..frames {
            let f = frame(test, width, height, t, D_REL);
            reference_pass.dispatch(
                &gpu,
                &f,
                &SssSettings { variant: SssVariant::Fixed { count: 128 }, ..reference_settings },
                t,
            )?;
            ref_smape.add(&f, reference_pass.results(&gpu)?, None);
        }
        let ref_smape = ref_smape.finish().smape;
        let mut variants = vec![
            ("AS".to_string(), SssVariant::Adaptive, None),
            ("AS+OCV".into(), SssVariant::OnlineCv, None),
            ("AS+CCV".into(), SssVariant::ConstantCv, None),
            ("fixed 64".into(), SssVariant::Fixed { count: 64 }, None),
        ];
        for &a in &afis_a {
            variants.push((
                format!("AFIS a={a}"),
                SssVariant::Adaptive,
                Some(Prefilter { a, ..Default::default() }),
            ));
        }
        variants.push(("separable".into(), SssVariant::Separable { taps: 25 }, None));
        for (name, variant, prefilter) in variants {
            let settings = SssSettings { variant, seed: 1, prefilter, ..Default::default() };
            let mut pass = SssPass::new(&gpu, width, height)?;
            let mut acc = Accumulator::default();
            let mut ms = 0.0;
            for t in 0..frames {
                let f = frame(test, width, height, t, D_REL);
                ms += pass.dispatch(&gpu, &f, &settings, t)?.iter().map(|p| p.ms).sum::<f64>();
                acc.add(
                    &f,
                    pass.results(&gpu)?,
                    references[t as usize].as_deref().map(|r| (r, peak)),
                );
            }
            let m = acc.finish();
            writeln!(
                table,
                "| {test:?} | {name} | {:.2} | {:.2} | {:.2} | {:.4} | {ref_smape:.4} |",
                m.mean_spp,
                ms / frames as f64,
                m.psnr_db,
                m.smape
            )?;
            eprintln!(
                "{test:?} {name}: {:.2} spp, {:.2} ms, {:.2} dB, SMAPE {:.4}",
                m.mean_spp,
                ms / frames as f64,
                m.psnr_db,
                m.smape
            );
            let mut pgm = format!("P5\n{width} {height}\n255\n").into_bytes();
            pgm.extend(
                m.count_image.iter().map(|c| (c / 64.0 * 255.0).round().clamp(0.0, 255.0) as u8),
            );
            std::fs::write(
                out.join(format!("counts_{test:?}_{}.pgm", name.replace([' ', '+', '='], "_"))),
                pgm,
            )?;
        }
    }
    std::fs::write(out.join("table.md"), &table)?;
    print!("{table}");
    Ok(())
}
