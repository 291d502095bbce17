//! Atomic writes of run outputs: every file appears whole or not at all
//! ([`write_atomic`]: a temporary file beside the target, renamed into place).

use std::path::Path;

use anyhow::{Context, Result};
use image::ImageEncoder;

use crate::tonemap;

/// The workspace's one atomic writer (it lives in `metrics`, below `frame` and `report`).
pub use metrics::atomic::write_atomic;

pub fn write_text(path: &Path, text: &str) -> Result<()> {
    write_atomic(path, |w| Ok(w.write_all(text.as_bytes())?))
}

pub fn write_json(path: &Path, value: &impl serde::Serialize) -> Result<()> {
    let text = serde_json::to_string_pretty(value)?;
    write_text(path, &text)
}

/// Linear HDR radiance as a 32-bit float RGBA OpenEXR file, in the workspace's one EXR layout
/// (`metrics::image::write_exr_pixels`: scan lines, which NVIDIA's FLIP tool reads).
pub fn write_exr(path: &Path, width: u32, height: u32, rgba: &[[f32; 4]]) -> Result<()> {
    metrics::image::write_exr_pixels(path, width, height, metrics::image::ExrPixels::Rgba(rgba))
}

/// Values as opaque grey RGBA pixels (a per-pixel count or statistic as an image).
pub fn grey_pixels(values: impl IntoIterator<Item = f32>) -> Vec<[f32; 4]> {
    values.into_iter().map(|v| [v, v, v, 1.0]).collect()
}

/// Tone-mapped 8-bit sRGB PNG of linear radiance.
pub fn write_png(
    path: &Path,
    width: u32,
    height: u32,
    rgba: &[[f32; 4]],
    exposure: f32,
) -> Result<()> {
    let ldr = tonemap::to_srgb8(rgba, exposure);
    write_atomic(path, |w| {
        image::codecs::png::PngEncoder::new(w)
            .write_image(&ldr, width, height, image::ExtendedColorType::Rgb8)
            .with_context(|| format!("encoding {}", path.display()))
    })
}

/// Writes display-ready values in [0, 1] (false-colour maps, masks) as 8-bit sRGB-encoded PNG
/// without tone mapping.
pub fn write_png_linear(path: &Path, width: u32, height: u32, rgba: &[[f32; 4]]) -> Result<()> {
    let bytes: Vec<u8> = rgba
        .iter()
        .flat_map(|p| [p[0], p[1], p[2]])
        .map(|v| (tonemap::linear_to_srgb(v.clamp(0.0, 1.0)) * 255.0 + 0.5) as u8)
        .collect();
    write_atomic(path, |w| {
        image::codecs::png::PngEncoder::new(w)
            .write_image(&bytes, width, height, image::ExtendedColorType::Rgb8)
            .with_context(|| format!("encoding {}", path.display()))
    })
}

/// Reads an RGBA32F EXR written by [`write_exr`].
pub fn read_exr(path: &Path) -> Result<(u32, u32, Vec<[f32; 4]>)> {
    let img =
        image::open(path).with_context(|| format!("reading {}", path.display()))?.into_rgba32f();
    let (w, h) = img.dimensions();
    let pixels = img.pixels().map(|p| p.0).collect();
    Ok((w, h, pixels))
}

#[cfg(test)]
mod tests {
    use super::*;
    use metrics::atomic::tmp_path;

    #[test]
    fn exr_round_trips_and_leaves_no_temporary() {
        let tmp = tempfile::tempdir().unwrap();
        let dir = tmp.path().to_path_buf();
        let path = dir.join("a/0000.exr");
        let px = vec![[0.25, 1.5, 1e3, 1.0], [0.0, 0.125, 7.0, 1.0]];
        write_exr(&path, 2, 1, &px).unwrap();
        let (w, h, back) = read_exr(&path).unwrap();
        assert_eq!((w, h), (2, 1));
        assert_eq!(back, px);
        assert!(!tmp_path(&path).exists());
        write_png(&dir.join("a/0000.png"), 2, 1, &px, 1.0).unwrap();
        let png = image::open(dir.join("a/0000.png")).unwrap().into_rgb8();
        assert_eq!(png.dimensions(), (2, 1));
    }

    #[test]
    fn failed_write_keeps_the_old_file() {
        let tmp = tempfile::tempdir().unwrap();
        let dir = tmp.path().to_path_buf();
        let path = dir.join("keep.txt");
        write_text(&path, "old").unwrap();
        let err = write_atomic(&path, |w| {
            w.write_all(b"half")?;
            anyhow::bail!("interrupted")
        });
        assert!(err.is_err());
        assert_eq!(std::fs::read_to_string(&path).unwrap(), "old");
        assert!(!tmp_path(&path).exists());
    }
}
