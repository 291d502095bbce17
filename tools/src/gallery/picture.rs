//! A failure's picture: the failing method's frame, the baseline's and the reference's where
//! the run has one, side by side at the run's size (PNG, a few KB).

use std::path::Path;

use anyhow::{Context, Result};
use image::{Rgb, RgbImage};

/// Pixels of dark grey between the panels.
const GAP: u32 = 2;

/// The panels (PNG files of one size) left to right into one PNG at `out`.
pub fn side_by_side(panels: &[&Path], out: &Path) -> Result<()> {
    let images: Vec<RgbImage> = panels
        .iter()
        .map(|p| {
            image::open(p).map(|i| i.to_rgb8()).with_context(|| format!("reading {}", p.display()))
        })
        .collect::<Result<_>>()?;
    let (w, h) = images.first().context("no panels")?.dimensions();
    if let Some((p, i)) = panels.iter().zip(&images).find(|(_, i)| i.dimensions() != (w, h)) {
        anyhow::bail!(
            "{} is {:?}, expected {w}x{h} as the first panel",
            p.display(),
            i.dimensions()
        );
    }
    let n = images.len() as u32;
    let mut strip = RgbImage::from_pixel(n * w + (n - 1) * GAP, h, Rgb([40, 40, 40]));
    for (k, img) in images.iter().enumerate() {
        image::imageops::replace(&mut strip, img, (k as u32 * (w + GAP)) as i64, 0);
    }
    if let Some(dir) = out.parent() {
        std::fs::create_dir_all(dir).with_context(|| format!("creating {}", dir.display()))?;
    }
    strip.save(out).with_context(|| format!("writing {}", out.display()))
}
