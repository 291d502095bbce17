//! Table 7.3's relations (thesis Sec. 7.4) on the CPU twin of the pass (`screen_pass::step`),
//! paired over seeds: per synthetic test (flash, toggle, boids) and seed, AS, AS+OCV, AS+CCV and
//! fixed 64 with the thesis's settings (`SssPassSettings::default()`: σ0² = 1e-4, α = 0.2, κ = 0.2,
//! ε_a = a_cv = 1e-6, ε_u = 0.01, [8, 64], gamma-encoded luminance); mean spp over SSS pixels
//! and frames, CPU ms per frame, PSNR of luminance against the pass at 2048 spp (analytic
//! inverse) on every 6th frame after frame 10, frame-to-frame SMAPE. Prints the per-seed rows,
//! the means, and each relation with its per-seed values; writes OUT/relations.md.
//!
//! cargo run --release -p sss --example sss_relations -- [WIDTH HEIGHT FRAMES SEEDS OUT [D_SCALE]]
//! (D_SCALE multiplies the profiles' d, relative to the image height: default 1, d = (0.15, 0.08,
//! 0.04) of the height).

#[path = "../tests/support/mod.rs"]
mod support;

use sss::sampling::luminance;
use sss::screen_pass::step;
use sss::{SssPassSettings, SssVariant};
use std::fmt::Write;
use std::time::Instant;
use support::evaluation::Accumulator;
use support::synthetic::{DynamicTest, frame};

const D_REL: [f32; 3] = [0.15, 0.08, 0.04];
const VARIANTS: [(&str, SssVariant); 4] = [
    ("AS", SssVariant::Adaptive),
    ("AS+OCV", SssVariant::OnlineCv),
    ("AS+CCV", SssVariant::ConstantCv),
    ("fixed 64", SssVariant::Fixed { count: 64 }),
];

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let arg = |i: usize, default: &str| args.get(i).cloned().unwrap_or_else(|| default.to_string());
    let (width, height, frames, seeds): (u32, u32, u32, u32) =
        (arg(0, "64").parse()?, arg(1, "36").parse()?, arg(2, "60").parse()?, arg(3, "3").parse()?);
    let out = std::path::PathBuf::from(arg(4, "sss_relations"));
    let d_scale: f32 = arg(5, "1").parse()?;
    let d_rel = D_REL.map(|d| d * d_scale);
    std::fs::create_dir_all(&out)?;
    let measured = |t: u32| t >= 10 && t % 6 == 4;
    let mut rows = format!(
        "{width}x{height}, {frames} frames, seeds 1..={seeds}, d = {d_rel:?} of the height, CPU twin\n\n| test | seed | variant | mean spp | CPU ms/frame | PSNR dB | SMAPE |\n|---|---|---|---|---|---|---|\n"
    );
    let mut means = String::from(
        "| test | variant | mean spp | CPU ms/frame | PSNR dB | SMAPE |\n|---|---|---|---|---|---|\n",
    );
    let mut relations = String::new();
    for test in [DynamicTest::Flash, DynamicTest::Toggle, DynamicTest::Boids] {
        let reference_settings = SssPassSettings {
            variant: SssVariant::Fixed { count: 2048 },
            fast_inverse: false,
            seed: 1000,
            ..Default::default()
        };
        let mut references = vec![None; frames as usize];
        let mut peak = 0.0f64;
        for t in (0..frames).filter(|&t| measured(t)) {
            let f = frame(test, width, height, t, d_rel);
            let r: Vec<[f32; 3]> =
                step(&f, &reference_settings, t, &[]).0.iter().map(|p| p.rgb).collect();
            peak = r.iter().map(|c| luminance(*c) as f64).fold(peak, f64::max);
            references[t as usize] = Some(r);
        }
        // [variant][seed] = (spp, ms, psnr, smape)
        let mut m = vec![vec![]; VARIANTS.len()];
        for seed in 1..=seeds {
            for (k, (name, variant)) in VARIANTS.iter().enumerate() {
                let settings = SssPassSettings { variant: *variant, seed, ..Default::default() };
                let (mut acc, mut history, mut ms) = (Accumulator::default(), vec![], 0.0);
                for t in 0..frames {
                    let f = frame(test, width, height, t, d_rel);
                    let start = Instant::now();
                    let (results, next) = step(&f, &settings, t, &history);
                    ms += start.elapsed().as_secs_f64() * 1e3;
                    history = next;
                    acc.add(&f, results, references[t as usize].as_deref().map(|r| (r, peak)));
                }
                let r = acc.finish();
                let row = (r.mean_spp, ms / frames as f64, r.psnr_db, r.smape);
                writeln!(
                    rows,
                    "| {test:?} | {seed} | {name} | {:.2} | {:.2} | {:.2} | {:.4} |",
                    row.0, row.1, row.2, row.3
                )?;
                eprintln!("{test:?} seed {seed} {name}: {row:?}");
                m[k].push(row);
            }
        }
        let mean = |k: usize, f: fn(&(f64, f64, f64, f64)) -> f64| {
            m[k].iter().map(f).sum::<f64>() / m[k].len() as f64
        };
        for (k, (name, _)) in VARIANTS.iter().enumerate() {
            writeln!(
                means,
                "| {test:?} | {name} | {:.2} | {:.2} | {:.2} | {:.4} |",
                mean(k, |r| r.0),
                mean(k, |r| r.1),
                mean(k, |r| r.2),
                mean(k, |r| r.3)
            )?;
        }
        let per_seed = |k: usize, f: fn(&(f64, f64, f64, f64)) -> f64| -> Vec<String> {
            m[k].iter().map(|r| format!("{:.2}", f(r))).collect()
        };
        let (a, o, c) = (0, 1, 2);
        let holds = |ok: bool| if ok { "holds" } else { "FAILS" };
        let all = |f: &dyn Fn(usize) -> bool| (0..seeds as usize).all(f);
        let spp = |k: usize, s: usize| m[k][s].0;
        let psnr = |k: usize, s: usize| m[k][s].2;
        writeln!(
            relations,
            "- {test:?}: CCV < OCV < AS per seed: {} (AS {:?}, OCV {:?}, CCV {:?})",
            holds(all(&|s| spp(c, s) < spp(o, s) && spp(o, s) < spp(a, s))),
            per_seed(a, |r| r.0),
            per_seed(o, |r| r.0),
            per_seed(c, |r| r.0)
        )?;
        match test {
            DynamicTest::Flash => writeln!(
                relations,
                "- Flash: OCV and CCV <= 0.6 x AS spp: {}; PSNR cost <= 2 dB: {} (PSNR AS {:?}, OCV {:?}, CCV {:?})",
                holds(all(&|s| spp(o, s) <= 0.6 * spp(a, s) && spp(c, s) <= 0.6 * spp(a, s))),
                holds(all(&|s| psnr(a, s) - psnr(o, s) <= 2.0 && psnr(a, s) - psnr(c, s) <= 2.0)),
                per_seed(a, |r| r.2),
                per_seed(o, |r| r.2),
                per_seed(c, |r| r.2)
            )?,
            _ => writeln!(
                relations,
                "- {test:?}: AS mean spp <= 0.6 x 64 = 38.4: {}",
                holds(all(&|s| spp(a, s) <= 38.4))
            )?,
        }
    }
    let text = format!("{rows}\nMeans over seeds:\n\n{means}\nRelations:\n\n{relations}");
    std::fs::write(out.join("relations.md"), &text)?;
    print!("{text}");
    Ok(())
}
