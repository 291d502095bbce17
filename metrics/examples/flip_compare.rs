//! `cargo run --release -p metrics --example flip_compare -- W H [SEEDS]`: HDR-FLIP by our
//! implementation (metrics::flip) and by the `flip-rs` crate against NVIDIA's `flip-evaluator`
//! (the reference, run as a subprocess) on synthetic HDR pairs: the mean FLIP of each (the
//! subprocess reports its mean, not its map) and each one's time (best of 3; NVIDIA's own
//! timer for the reference).

use std::time::Instant;

use metrics::reference_flip::run_reference_flip;
use metrics::synthetic::synthetic_hdr_pair;
use metrics::{DEFAULT_PPD, flip_hdr, write_exr};

fn best_ms(mut f: impl FnMut()) -> f64 {
    (0..3)
        .map(|_| {
            let t = Instant::now();
            f();
            t.elapsed().as_secs_f64() * 1e3
        })
        .fold(f64::INFINITY, f64::min)
}

fn main() -> anyhow::Result<()> {
    let args: Vec<u32> = std::env::args().skip(1).map(|a| a.parse()).collect::<Result<_, _>>()?;
    let [w, h, rest @ ..] = args.as_slice() else {
        anyhow::bail!("usage: flip_compare W H [SEEDS]")
    };
    let seeds = rest.first().copied().unwrap_or(3);
    let dir = std::env::temp_dir().join(format!("flip-compare-{}", std::process::id()));
    std::fs::create_dir_all(&dir)?;
    println!(
        "| seed | NVIDIA mean | ours mean | flip-rs mean | ours ms | flip-rs ms | NVIDIA ms |"
    );
    println!("|---:|---:|---:|---:|---:|---:|---:|");
    for seed in 0..seeds {
        let (reference, test) = synthetic_hdr_pair(*w, *h, 7 + seed);
        let (rp, tp) = (dir.join("r.exr"), dir.join("t.exr"));
        write_exr(&reference, &rp)?;
        write_exr(&test, &tp)?;
        let (nv_ms, nv_mean) = run_reference_flip(&rp, &tp, DEFAULT_PPD)?;
        let mut ours = 0.0;
        let ours_ms = best_ms(|| ours = flip_hdr(&reference, &test, DEFAULT_PPD).mean);
        let flat = |i: &metrics::Image| i.rgb.iter().flatten().copied().collect::<Vec<f32>>();
        let r = flip_rs::RgbImage::new(*w as usize, *h as usize, flat(&reference))?;
        let t = flip_rs::RgbImage::new(*w as usize, *h as usize, flat(&test))?;
        let mut options = flip_rs::HdrOptions::default();
        options.ppd = DEFAULT_PPD;
        options.return_exposure_map = false;
        let mut theirs = 0.0;
        let theirs_ms = best_ms(|| {
            theirs = flip_rs::hdr_flip(&r, &t, options)
                .map(|x| x.error_map.statistics().mean)
                .unwrap_or(f32::NAN)
        });
        println!(
            "| {seed} | {nv_mean:.6} | {ours:.6} | {theirs:.6} | {ours_ms:.1} | {theirs_ms:.1} | {nv_ms:.1} |"
        );
    }
    std::fs::remove_dir_all(&dir).ok();
    Ok(())
}
