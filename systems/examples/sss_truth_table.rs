//! FLIP of each SSS variant against the random-walk ground truth (the scenario's reference with
//! `reference: (random_walk: true)`, media::gpu::SubsurfacePathPass) and against the 2048-sample
//! screen-space pass (`pass_2048`), side by side: the diffusion model's error beside each
//! variant's noise. Per run folder (one seed each) and every frame with a reference: HDR-FLIP
//! (metrics::flip_hdr, the default pixels per degree) of the whole image and its mean over the
//! SSS pixels (where pass_2048's count image is non-zero); the table gives each method's mean
//! over frames and seeds and the seeds' spread.
//!
//! cargo run -p systems --example sss_truth_table -- RUN...   (scenarios/sss_truth.ron)

use std::path::Path;

use anyhow::{Context, Result, bail};
use metrics::{DEFAULT_PPD, Image, flip_hdr};
use systems::output::read_exr;
use systems::run_folder::RunFolder;

const PASS: &str = "pass_2048";

fn image(path: &Path) -> Result<Image> {
    let (w, h, px) = read_exr(path)?;
    Ok(Image::new(w, h, px.iter().map(|p| [p[0], p[1], p[2]]).collect()))
}

/// Methods in the order frames.csv lists them.
fn methods(folder: &RunFolder) -> Result<Vec<String>> {
    let path = folder.frames_csv();
    let text =
        std::fs::read_to_string(&path).with_context(|| format!("reading {}", path.display()))?;
    let mut lines = text.lines();
    let header: Vec<&str> = lines.next().unwrap_or("").split(',').collect();
    let col = header
        .iter()
        .position(|h| *h == "method")
        .with_context(|| format!("{}: no column method", path.display()))?;
    let mut out: Vec<String> = vec![];
    for l in lines {
        let m = l.split(',').nth(col).unwrap_or("").to_string();
        if !out.contains(&m) {
            out.push(m);
        }
    }
    Ok(out)
}

/// Per method: (whole-image FLIP vs truth, vs pass_2048, SSS-pixel FLIP vs truth, vs pass_2048),
/// means over the run's reference frames.
fn run(dir: &Path) -> Result<Vec<(String, [f64; 4])>> {
    let folder = RunFolder::new(dir);
    let methods = methods(&folder)?;
    if !methods.iter().any(|m| m == PASS) {
        bail!("{}: no method {PASS}; expected the SSS scenario's 2048-sample pass", dir.display());
    }
    let frames: Vec<u32> = (0..10_000).filter(|f| folder.reference(*f, "exr").exists()).collect();
    if frames.is_empty() {
        bail!(
            "{}: no reference frames; expected reference: (random_walk: true, ...)",
            dir.display()
        );
    }
    let mut out: Vec<(String, [f64; 4])> = methods.iter().map(|m| (m.clone(), [0.0; 4])).collect();
    for &f in &frames {
        let truth = image(&folder.reference(f, "exr"))?;
        let pass = image(&folder.frame(PASS, f, "exr"))?;
        let mask_path = folder.method_image(PASS, "sample_count", f, "png");
        let mask: Vec<bool> = image::open(&mask_path)
            .with_context(|| format!("reading {}", mask_path.display()))?
            .into_luma8()
            .pixels()
            .map(|p| p.0[0] > 0)
            .collect();
        let masked = |map: &[f32]| {
            let (s, n) = map
                .iter()
                .zip(&mask)
                .filter(|(_, m)| **m)
                .fold((0.0, 0usize), |(s, n), (v, _)| (s + f64::from(*v), n + 1));
            s / n.max(1) as f64
        };
        for (m, acc) in &mut out {
            let img = image(&folder.frame(m, f, "exr"))?;
            let (a, b) = (flip_hdr(&truth, &img, DEFAULT_PPD), flip_hdr(&pass, &img, DEFAULT_PPD));
            let v = [a.mean, b.mean, masked(&a.map), masked(&b.map)];
            for (a, v) in acc.iter_mut().zip(v) {
                *a += v / frames.len() as f64;
            }
        }
    }
    Ok(out)
}

fn main() -> Result<()> {
    let dirs: Vec<String> = std::env::args().skip(1).collect();
    if dirs.is_empty() {
        bail!("usage: sss_truth_table RUN...; expected run folders of scenarios/sss_truth.ron");
    }
    let runs: Vec<Vec<(String, [f64; 4])>> =
        dirs.iter().map(|d| run(Path::new(d))).collect::<Result<_>>()?;
    println!(
        "| method | FLIP vs random walk | FLIP vs pass_2048 | SSS pixels: vs random walk | SSS pixels: vs pass_2048 |"
    );
    println!("|---|---|---|---|---|");
    for (i, (m, _)) in runs[0].iter().enumerate() {
        let cell = |k: usize| {
            let v: Vec<f64> = runs.iter().map(|r| r[i].1[k]).collect();
            let mean = v.iter().sum::<f64>() / v.len() as f64;
            let (lo, hi) = v.iter().fold((f64::MAX, f64::MIN), |(a, b), x| (a.min(*x), b.max(*x)));
            format!("{mean:.4} ({lo:.4}-{hi:.4})")
        };
        println!("| {m} | {} | {} | {} | {} |", cell(0), cell(1), cell(2), cell(3));
    }
    Ok(())
}
