//! Images of a run for the report: FLIP error maps (magma) of every method at the frames that
//! have a reference, and side-by-side crops (reference, then each method; error maps below)
//! of every region of interest.

use std::path::{Path, PathBuf};

use anyhow::Context;
use image::{Rgb, RgbImage};
use metrics::{DEFAULT_PPD, Image, Region, flip_hdr, flip_ldr, load_image, magma};

use crate::run::{Manifest, frame_file};

pub struct MethodImage {
    pub method: String,
    /// The method's frame for display (PNG).
    pub image: PathBuf,
    pub flip_map: PathBuf,
    /// The FLIP map's values, row by row.
    pub flip: Vec<f32>,
    pub flip_mean: f64,
}

pub struct FrameImages {
    pub frame: u32,
    pub reference: PathBuf,
    pub methods: Vec<MethodImage>,
    /// (region name, side-by-side PNG).
    pub crops: Vec<(String, PathBuf)>,
}

/// The image of a frame: EXR when present (HDR-FLIP), else PNG (LDR-FLIP); plus a PNG to show.
fn load_frame(
    run_dir: &Path,
    method: Option<&str>,
    frame: u32,
    charts: &Path,
) -> anyhow::Result<Option<(Image, bool, PathBuf)>> {
    let exr = frame_file(run_dir, method, frame, "exr");
    let png = frame_file(run_dir, method, frame, "png");
    let (img, hdr) = if exr.exists() {
        (load_image(&exr)?, true)
    } else if png.exists() {
        (load_image(&png)?, false)
    } else {
        return Ok(None);
    };
    let shown = if png.exists() {
        png
    } else {
        let p = charts.join(format!("{}_{frame:04}.png", method.unwrap_or("reference")));
        metrics::write_png_srgb(&img, &p)?;
        p
    };
    Ok(Some((img, hdr, shown)))
}

/// Scales an RGB image up by an integer factor (nearest neighbour keeps pixels crisp).
fn upscale(img: &RgbImage, factor: u32) -> RgbImage {
    RgbImage::from_fn(img.width() * factor, img.height() * factor, |x, y| {
        *img.get_pixel(x / factor, y / factor)
    })
}

fn to_rgb8(img: &Image) -> RgbImage {
    RgbImage::from_fn(img.width, img.height, |x, y| {
        Rgb(img
            .get(x, y)
            .map(|c| (metrics::image::linear_to_srgb(c.clamp(0.0, 1.0)) * 255.0 + 0.5) as u8))
    })
}

fn map_to_rgb8(map: &[f32], width: u32, height: u32) -> RgbImage {
    RgbImage::from_fn(width, height, |x, y| Rgb(magma(map[(y * width + x) as usize])))
}

/// Tiles images left to right in rows, with a white gap.
fn tile(rows: &[Vec<RgbImage>]) -> RgbImage {
    const GAP: u32 = 4;
    let w = rows.iter().map(|r| r.iter().map(|i| i.width() + GAP).sum::<u32>()).max().unwrap_or(0);
    let h = rows.iter().map(|r| r.iter().map(|i| i.height()).max().unwrap_or(0) + GAP).sum::<u32>();
    let mut out = RgbImage::from_pixel(w.max(1), h.max(1), Rgb([255, 255, 255]));
    let mut y0 = 0;
    for row in rows {
        let mut x0 = 0;
        for img in row {
            image::imageops::replace(&mut out, img, x0 as i64, y0 as i64);
            x0 += img.width() + GAP;
        }
        y0 += row.iter().map(|i| i.height()).max().unwrap_or(0) + GAP;
    }
    out
}

pub fn write_frame_images(
    run_dir: &Path,
    manifest: &Manifest,
    methods: &[String],
) -> anyhow::Result<Vec<FrameImages>> {
    let charts = run_dir.join("charts");
    std::fs::create_dir_all(&charts)
        .with_context(|| format!("cannot create {}", charts.display()))?;
    let mut out = Vec::new();
    for &frame in &manifest.reference.frames {
        let Some((reference, ref_hdr, ref_shown)) = load_frame(run_dir, None, frame, &charts)?
        else {
            continue;
        };
        let mut entries = Vec::new();
        let mut loaded = Vec::new();
        for method in methods {
            let Some((img, hdr, shown)) = load_frame(run_dir, Some(method), frame, &charts)? else {
                continue;
            };
            if (img.width, img.height) != (reference.width, reference.height) {
                anyhow::bail!(
                    "{}: frame {frame} of {method} is {}x{}, the reference is {}x{}",
                    run_dir.display(),
                    img.width,
                    img.height,
                    reference.width,
                    reference.height
                );
            }
            let flip = if hdr && ref_hdr {
                flip_hdr(&reference, &img, DEFAULT_PPD)
            } else {
                flip_ldr(&reference, &img, DEFAULT_PPD)
            };
            let map_path = charts.join(format!("flip_{method}_{frame:04}.png"));
            metrics::write_map_png(&flip.map, img.width, img.height, &map_path)?;
            entries.push(MethodImage {
                method: method.clone(),
                image: shown,
                flip_map: map_path,
                flip: flip.map.clone(),
                flip_mean: flip.mean,
            });
            loaded.push((img, flip.map));
        }
        let full = Region {
            name: "full".into(),
            x: 0,
            y: 0,
            width: reference.width,
            height: reference.height,
        };
        let regions: Vec<Region> =
            if manifest.regions.is_empty() { vec![full] } else { manifest.regions.clone() };
        let mut crops = Vec::new();
        for region in &regions {
            let r = region.crop(&reference);
            if r.is_empty() {
                continue;
            }
            let factor = (160 / r.height.max(1)).clamp(1, 8);
            let mut top = vec![upscale(&to_rgb8(&r), factor)];
            let mut bottom = vec![RgbImage::from_pixel(
                r.width * factor,
                r.height * factor,
                Rgb([255, 255, 255]),
            )];
            for (img, map) in &loaded {
                top.push(upscale(&to_rgb8(&region.crop(img)), factor));
                let map_img =
                    Image::new(img.width, img.height, map.iter().map(|&v| [v, v, v]).collect());
                let m = region.crop(&map_img);
                let values: Vec<f32> = m.rgb.iter().map(|p| p[0]).collect();
                bottom.push(upscale(&map_to_rgb8(&values, m.width, m.height), factor));
            }
            let path = charts.join(format!("crops_{}_{frame:04}.png", region.name));
            let mut png = std::io::Cursor::new(Vec::new());
            tile(&[top, bottom]).write_to(&mut png, image::ImageFormat::Png)?;
            metrics::atomic::write_bytes(&path, png.into_inner())?;
            crops.push((region.name.clone(), path));
        }
        out.push(FrameImages { frame, reference: ref_shown, methods: entries, crops });
    }
    Ok(out)
}
