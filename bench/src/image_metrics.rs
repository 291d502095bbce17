//! Speed benchmark: SMAPE and FLIP at 1280x720 on a synthetic HDR pair, and NVIDIA's reference
//! FLIP (`flip` from the `flip-evaluator` Python package) on the same pair when installed, and
//! per frame at 160x90 and at the bench size: FLIP, ColorVideoVDP's JOD of a short video of such
//! pairs, and the authors' `cvvdp` (PyTorch, CPU) on a video of that size where it is installed.
//! Run it from a release build; it is a measurement, not a test.

use std::path::PathBuf;
use std::time::Instant;

use metrics::reference_flip::run_reference_flip;
use metrics::smape::DEFAULT_EPS;
use metrics::synthetic::synthetic_hdr_pair;
use metrics::{DEFAULT_PPD, flip_hdr, smape, write_exr};
use serde::Serialize;

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
    /// ColorVideoVDP (metrics::cvvdp): ms per frame of a `JOD_FRAMES`-frame video, per size.
    pub jod: Vec<JodTiming>,
}

#[derive(Clone, Debug, Serialize)]
pub struct JodTiming {
    pub width: u32,
    pub height: u32,
    pub frames: u32,
    pub ms_per_frame: f64,
    pub jod: f64,
    /// HDR-FLIP of one frame's pair at this size, beside JOD's cost per frame.
    pub flip_ms: f64,
    /// `cvvdp` on the CPU (one torch thread), ms per frame of a `frames`-frame video of this
    /// size, or why there is none ("cvvdp not installed").
    pub cvvdp: Result<f64, String>,
}

/// Frames of the timed JOD video: enough for its temporal filters to matter, few enough to time.
pub const JOD_FRAMES: u32 = 8;

/// JOD of a video whose test frames are the synthetic pair with fresh noise in every frame.
fn time_jod(width: u32, height: u32, repeats: u32) -> anyhow::Result<JodTiming> {
    let pairs: Vec<_> = (0..JOD_FRAMES).map(|f| synthetic_hdr_pair(width, height, 7 + f)).collect();
    let reference: Vec<_> = pairs.iter().map(|p| p.0.clone()).collect();
    let test: Vec<_> = pairs.iter().map(|p| p.1.clone()).collect();
    let settings = metrics::CvvdpSettings::default();
    let mut jod = Ok(0.0);
    let ms = best_ms(repeats, || {
        jod = metrics::jod(&reference, &test, 30.0, &settings, false).map(|r| r.jod)
    });
    let flip_ms = best_ms(repeats, || {
        std::hint::black_box(flip_hdr(&reference[0], &test[0], DEFAULT_PPD));
    });
    Ok(JodTiming {
        width,
        height,
        frames: JOD_FRAMES,
        ms_per_frame: ms / JOD_FRAMES as f64,
        jod: jod?,
        flip_ms,
        cvvdp: time_cvvdp(width, height),
    })
}

/// `scripts/cvvdp_fixtures.py time`: the authors' ColorVideoVDP on the CPU, ms per frame.
fn time_cvvdp(width: u32, height: u32) -> Result<f64, String> {
    let installed = std::process::Command::new(metrics::python::interpreter())
        .args(["-c", "import pycvvdp, torch"])
        .output()
        .is_ok_and(|o| o.status.success());
    if !installed {
        return Err("cvvdp not installed".into());
    }
    let script = concat!(env!("CARGO_MANIFEST_DIR"), "/../scripts/cvvdp_fixtures.py");
    let out = std::process::Command::new(metrics::python::interpreter())
        .arg(script)
        .args(["time", &width.to_string(), &height.to_string(), &JOD_FRAMES.to_string()])
        .output()
        .map_err(|e| format!("cannot run {script}: {e}"))?;
    let text = String::from_utf8_lossy(&out.stdout);
    // "cvvdp WxH N frames, 1 thread: S s (MS ms/frame)"
    text.split('(')
        .nth(1)
        .and_then(|t| t.split_whitespace().next())
        .and_then(|ms| ms.parse().ok())
        .ok_or_else(|| format!("cvvdp failed: {text}{}", String::from_utf8_lossy(&out.stderr)))
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
    let mut jod = Vec::new();
    if !args.smape_only {
        for (w, h) in [(160, 90), (args.width, args.height)] {
            if jod.iter().all(|t: &JodTiming| (t.width, t.height) != (w, h)) {
                jod.push(time_jod(w, h, args.repeats.min(3))?);
            }
        }
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
        jod,
    })
}
