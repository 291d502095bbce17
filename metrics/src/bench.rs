//! Speed benchmark: SMAPE and FLIP at 1280x720 on a synthetic HDR pair, and NVIDIA's reference
//! FLIP (`flip` from the `flip-evaluator` Python package) on the same pair when installed.
//! Run it from a release build; it is a measurement, not a test.

use std::path::PathBuf;
use std::process::Command;
use std::time::Instant;

use anyhow::Context;
use serde::Serialize;

use crate::flip::{DEFAULT_PPD, flip_hdr};
use crate::image::{Image, write_exr};
use crate::smape::{DEFAULT_EPS, smape};

#[derive(Clone, Debug, clap::Args)]
pub struct BenchArgs {
    #[arg(long, default_value_t = 1280)]
    pub width: u32,
    #[arg(long, default_value_t = 720)]
    pub height: u32,
    /// Timed repetitions; the best is reported.
    #[arg(long, default_value_t = 5)]
    pub repeats: u32,
    /// Skip NVIDIA's reference implementation.
    #[arg(long)]
    pub no_reference: bool,
    /// Time SMAPE only.
    #[arg(long)]
    pub smape_only: bool,
}

#[derive(Clone, Debug, Serialize)]
pub struct BenchReport {
    pub width: u32,
    pub height: u32,
    pub threads: usize,
    pub smape_ms: f64,
    pub flip_hdr_ms: Option<f64>,
    pub flip_hdr_mean: Option<f64>,
    /// NVIDIA's FLIP on the same pair: its own reported evaluation time, and its mean.
    pub reference_flip_ms: Option<f64>,
    pub reference_flip_mean: Option<f64>,
    /// reference time / our time (> 1: we are faster).
    pub speedup: Option<f64>,
}

/// Deterministic integer hash to [0, 1).
pub fn hash01(x: u32, y: u32, seed: u32) -> f32 {
    let mut h =
        x.wrapping_mul(0x8da6_b343) ^ y.wrapping_mul(0xd816_3841) ^ seed.wrapping_mul(0xcb1a_b31f);
    h ^= h >> 16;
    h = h.wrapping_mul(0x7feb_352d);
    h ^= h >> 15;
    h = h.wrapping_mul(0x846c_a68b);
    h ^= h >> 16;
    (h >> 8) as f32 / (1u32 << 24) as f32
}

/// A rendered-looking HDR reference (gradient sky, bright emitter, textured floor) and a noisy,
/// slightly darker test image of it.
pub fn synthetic_hdr_pair(width: u32, height: u32, seed: u32) -> (Image, Image) {
    let reference = Image::from_fn(width, height, |x, y| {
        let u = x as f32 / width as f32;
        let v = y as f32 / height as f32;
        let (dx, dy) = (u - 0.7, v - 0.25);
        if dx * dx + dy * dy < 0.004 {
            return [40.0, 36.0, 30.0];
        }
        if v < 0.5 {
            [0.3 + 0.5 * v, 0.5 + 0.4 * v, 1.2 - v]
        } else {
            let checker = ((x / 16 + y / 16) % 2) as f32;
            let shade = 0.05 + 0.6 * checker * (1.0 - v);
            [shade, shade * 0.8, shade * 0.6]
        }
    });
    let test = Image::from_fn(width, height, |x, y| {
        let noise = 1.0 + 0.6 * (hash01(x, y, seed) - 0.5);
        reference.get(x, y).map(|c| c * noise * 0.95)
    });
    (reference, test)
}

fn best_ms(repeats: u32, mut f: impl FnMut()) -> f64 {
    (0..repeats.max(1))
        .map(|_| {
            let t = Instant::now();
            f();
            t.elapsed().as_secs_f64() * 1e3
        })
        .fold(f64::INFINITY, f64::min)
}

/// NVIDIA's FLIP command-line tool, run through the Python module (no reliance on PATH entry points).
pub fn reference_flip_command() -> Command {
    let mut c = Command::new("python3");
    c.args(["-m", "flip_evaluator.flip_python_api"]);
    c
}

/// Whether NVIDIA's reference FLIP is installed.
pub fn reference_flip_available() -> bool {
    reference_flip_command().arg("-h").output().is_ok_and(|o| o.status.success())
}

/// Runs NVIDIA's `flip` tool on two EXR files; returns (its evaluation time in ms, mean FLIP).
pub fn run_reference_flip(
    reference: &std::path::Path,
    test: &std::path::Path,
    ppd: f32,
) -> anyhow::Result<(f64, f64)> {
    let out = reference_flip_command()
        .args(["-r".as_ref(), reference.as_os_str(), "-t".as_ref(), test.as_os_str()])
        .args(["-ppd", &ppd.to_string(), "-nerm", "-nexm", "-v", "2"])
        .output()
        .context(
            "cannot run python3 -m flip_evaluator.flip_python_api (pip install flip-evaluator)",
        )?;
    let text = String::from_utf8_lossy(&out.stdout);
    anyhow::ensure!(
        out.status.success(),
        "`flip` failed: {}{}",
        text,
        String::from_utf8_lossy(&out.stderr)
    );
    let number_after = |key: &str| -> Option<f64> {
        let line = text.lines().find(|l| l.contains(key))?;
        line.split(|c: char| !(c.is_ascii_digit() || c == '.' || c == '-' || c == 'e'))
            .filter_map(|s| s.parse().ok())
            .next_back()
    };
    let mean = number_after("Mean:").context(format!("no 'Mean:' in flip's output:\n{text}"))?;
    let seconds = number_after("Evaluation time:")
        .context(format!("no 'Evaluation time:' in flip's output:\n{text}"))?;
    Ok((seconds * 1e3, mean))
}

pub fn bench(args: &BenchArgs) -> anyhow::Result<BenchReport> {
    let (reference, test) = synthetic_hdr_pair(args.width, args.height, 7);
    let smape_ms = best_ms(args.repeats.max(10), || {
        std::hint::black_box(smape(&test, &reference, DEFAULT_EPS));
    });
    let (mut flip_hdr_ms, mut flip_hdr_mean) = (None, None);
    if !args.smape_only {
        flip_hdr_ms = Some(best_ms(args.repeats, || {
            flip_hdr_mean = Some(flip_hdr(&reference, &test, DEFAULT_PPD).mean)
        }));
    }
    let (mut reference_flip_ms, mut reference_flip_mean) = (None, None);
    if !args.no_reference && !args.smape_only {
        let dir: PathBuf =
            std::env::temp_dir().join(format!("flicker-bench-{}", std::process::id()));
        std::fs::create_dir_all(&dir)?;
        write_exr(&reference, dir.join("reference.exr"))?;
        write_exr(&test, dir.join("test.exr"))?;
        let mut best = f64::INFINITY;
        for _ in 0..args.repeats.max(1) {
            let (ms, mean) =
                run_reference_flip(&dir.join("reference.exr"), &dir.join("test.exr"), DEFAULT_PPD)?;
            best = best.min(ms);
            reference_flip_mean = Some(mean);
        }
        reference_flip_ms = Some(best);
        std::fs::remove_dir_all(&dir).ok();
    }
    Ok(BenchReport {
        width: args.width,
        height: args.height,
        threads: rayon::current_num_threads(),
        smape_ms,
        flip_hdr_ms,
        flip_hdr_mean,
        speedup: reference_flip_ms.zip(flip_hdr_ms).map(|(r, ours)| r / ours),
        reference_flip_ms,
        reference_flip_mean,
    })
}
