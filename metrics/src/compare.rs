//! `compare REFERENCE TEST`: FLIP, SMAPE and PSNR of two image files, like NVIDIA's FLIP tool.

use std::path::{Path, PathBuf};

use anyhow::{Context, bail};
use serde::Serialize;

use crate::flip::{ExposureRange, Percentiles, flip_hdr, flip_ldr};
use crate::image::load_image;
use crate::smape::smape;
use crate::{colormap, error};

#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize)]
#[serde(rename_all = "lowercase")]
pub enum FlipMode {
    Ldr,
    Hdr,
}

impl FlipMode {
    /// Each mode's name, as `FromStr` reads it and the JSON writes it.
    pub const NAMES: [&str; 2] = ["ldr", "hdr"];
}

impl std::str::FromStr for FlipMode {
    type Err = String;

    fn from_str(s: &str) -> Result<Self, String> {
        match s {
            "ldr" => Ok(Self::Ldr),
            "hdr" => Ok(Self::Hdr),
            _ => Err(format!("expected one of {}, got '{s}'", Self::NAMES.join(", "))),
        }
    }
}

/// What [`compare`] reads, measures and writes (`flicker compare`'s options).
#[derive(Clone, Debug)]
pub struct CompareOptions {
    /// Reference image (.png = sRGB, .exr = linear).
    pub reference: PathBuf,
    /// Test image, same size as the reference.
    pub test: PathBuf,
    /// LDR-FLIP or HDR-FLIP; `None`: hdr for EXR references, ldr for PNG.
    pub mode: Option<FlipMode>,
    /// Pixels per degree of the viewing setup ([`crate::DEFAULT_PPD`]: 0.7 m from a 0.7 m wide
    /// 3840 px monitor).
    pub ppd: f32,
    /// Write the FLIP error map here as a magma PNG.
    pub map: Option<PathBuf>,
    /// Print JSON instead of text.
    pub json: bool,
    /// ε of SMAPE's denominator ([`crate::smape::DEFAULT_EPS`] by default).
    pub eps: f32,
}

/// What `compare` measures.
#[derive(Clone, Debug, Serialize)]
pub struct Comparison {
    pub reference: PathBuf,
    pub test: PathBuf,
    pub width: u32,
    pub height: u32,
    pub mode: FlipMode,
    pub ppd: f32,
    pub flip_mean: f64,
    pub flip_percentiles: Percentiles,
    pub exposures: Option<ExposureRange>,
    pub smape: f64,
    pub mse: f64,
    pub relative_mse: f64,
    pub psnr: f64,
    #[serde(skip)]
    pub flip_map: Vec<f32>,
}

fn default_mode(reference: &Path) -> FlipMode {
    let exr = reference
        .extension()
        .and_then(|e| e.to_str())
        .is_some_and(|e| e.eq_ignore_ascii_case("exr"));
    if exr { FlipMode::Hdr } else { FlipMode::Ldr }
}

/// Loads both images and measures them.
pub fn compare_files(
    reference: &Path,
    test: &Path,
    mode: Option<FlipMode>,
    ppd: f32,
    eps: f32,
) -> anyhow::Result<Comparison> {
    if ppd.is_nan() || ppd <= 0.0 {
        bail!("--ppd must be positive, got {ppd}");
    }
    let r = load_image(reference)?;
    let t = load_image(test)?;
    if (r.width, r.height) != (t.width, t.height) {
        bail!(
            "{} is {}x{} but {} is {}x{}: images must have the same size",
            reference.display(),
            r.width,
            r.height,
            test.display(),
            t.width,
            t.height
        );
    }
    let mode = mode.unwrap_or_else(|| default_mode(reference));
    let flip = match mode {
        FlipMode::Ldr => flip_ldr(&r, &t, ppd),
        FlipMode::Hdr => flip_hdr(&r, &t, ppd),
    };
    let mse = error::mse(&r, &t);
    Ok(Comparison {
        reference: reference.to_path_buf(),
        test: test.to_path_buf(),
        width: r.width,
        height: r.height,
        mode,
        ppd,
        flip_mean: flip.mean,
        flip_percentiles: flip.percentiles,
        exposures: flip.exposures,
        smape: smape(&t, &r, eps).mean,
        mse,
        relative_mse: error::relative_mse(&r, &t),
        psnr: error::psnr_from_mse(mse, 1.0),
        flip_map: flip.map,
    })
}

/// Runs `compare`: prints the metrics (text or JSON) and writes the error map if asked.
pub fn compare(args: &CompareOptions) -> anyhow::Result<()> {
    let c = compare_files(&args.reference, &args.test, args.mode, args.ppd, args.eps)?;
    if let Some(path) = &args.map {
        colormap::write_map_png(&c.flip_map, c.width, c.height, path)?;
    }
    if args.json {
        println!("{}", serde_json::to_string_pretty(&c).context("serialising the comparison")?);
    } else {
        println!("{}", text_report(&c));
    }
    Ok(())
}

pub fn text_report(c: &Comparison) -> String {
    let mut s = format!(
        "{} vs {} ({}x{}, {:?}-FLIP at {:.2} ppd)\n",
        c.reference.display(),
        c.test.display(),
        c.width,
        c.height,
        c.mode,
        c.ppd
    );
    s += &format!(
        "FLIP  mean {:.6}  median {:.6}  p95 {:.6}  max {:.6}\n",
        c.flip_mean, c.flip_percentiles.p50, c.flip_percentiles.p95, c.flip_percentiles.max
    );
    if let Some(e) = c.exposures {
        s += &format!("      exposures {:.4} to {:.4} stops, {} steps\n", e.start, e.stop, e.count);
    }
    s += &format!(
        "SMAPE {:.6}\nPSNR  {:.3} dB (MSE {:.6e}, relative MSE {:.6e})",
        c.smape, c.psnr, c.mse, c.relative_mse
    );
    s
}
