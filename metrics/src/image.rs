//! The image type all metrics take, and PNG/EXR input/output.
//!
//! Pixels are linear RGB. PNG files are sRGB-encoded, so they are decoded to linear on load and
//! encoded on save; EXR files are already linear.

use std::path::Path;

use anyhow::{Context, bail};

/// A linear-RGB image (HDR, or LDR in [0, 1]), row-major, top row first.
#[derive(Clone, Debug, PartialEq)]
pub struct Image {
    pub width: u32,
    pub height: u32,
    pub rgb: Vec<[f32; 3]>,
}

impl Image {
    pub fn new(width: u32, height: u32, rgb: Vec<[f32; 3]>) -> Self {
        assert_eq!(
            rgb.len(),
            width as usize * height as usize,
            "pixel count must be width * height"
        );
        Self { width, height, rgb }
    }

    pub fn filled(width: u32, height: u32, value: [f32; 3]) -> Self {
        Self::new(width, height, vec![value; width as usize * height as usize])
    }

    pub fn from_fn(width: u32, height: u32, f: impl Fn(u32, u32) -> [f32; 3]) -> Self {
        let rgb = (0..height)
            .flat_map(|y| (0..width).map(move |x| (x, y)))
            .map(|(x, y)| f(x, y))
            .collect();
        Self::new(width, height, rgb)
    }

    pub fn len(&self) -> usize {
        self.rgb.len()
    }

    pub fn is_empty(&self) -> bool {
        self.rgb.is_empty()
    }

    pub fn get(&self, x: u32, y: u32) -> [f32; 3] {
        self.rgb[y as usize * self.width as usize + x as usize]
    }

    /// Panics with both sizes when two images that must be compared pixel by pixel differ.
    pub(crate) fn assert_same_size(&self, other: &Image, what: &str) {
        assert!(
            self.width == other.width && self.height == other.height,
            "{what}: images differ in size ({}x{} vs {}x{})",
            self.width,
            self.height,
            other.width,
            other.height
        );
    }
}

/// sRGB transfer function, decoding (IEC 61966-2-1).
pub fn srgb_to_linear(c: f32) -> f32 {
    if c <= 0.04045 { c / 12.92 } else { ((c + 0.055) / 1.055).powf(2.4) }
}

/// sRGB transfer function, encoding.
pub fn linear_to_srgb(c: f32) -> f32 {
    if c <= 0.003_130_8 { c * 12.92 } else { 1.055 * c.powf(1.0 / 2.4) - 0.055 }
}

fn extension(path: &Path) -> String {
    path.extension().and_then(|e| e.to_str()).unwrap_or("").to_ascii_lowercase()
}

/// Loads a PNG (sRGB, converted to linear) or an EXR (linear) as an [`Image`].
pub fn load_image(path: impl AsRef<Path>) -> anyhow::Result<Image> {
    let path = path.as_ref();
    let ext = extension(path);
    if ext != "png" && ext != "exr" {
        bail!("{}: expected a .png or .exr image", path.display());
    }
    if ext == "exr" {
        check_exr_size(path)?;
    }
    let decoded =
        ::image::open(path).with_context(|| format!("cannot read image {}", path.display()))?;
    let (width, height) = (decoded.width(), decoded.height());
    let rgb = if ext == "png" {
        // 8-bit sRGB like the FLIP reference tool reads it; 16-bit keeps its precision.
        let px = decoded.to_rgb32f();
        px.pixels()
            .map(|p| [srgb_to_linear(p[0]), srgb_to_linear(p[1]), srgb_to_linear(p[2])])
            .collect()
    } else {
        let px = decoded.to_rgb32f();
        px.pixels().map(|p| [p[0], p[1], p[2]]).collect()
    };
    Ok(Image::new(width, height, rgb))
}

/// The most bytes one decoded image may take: the `image` crate's default allocation limit, which
/// it applies to the display window of an EXR but not to the data window the `exr` crate
/// decodes (a header claiming a data window of 10^8 columns made it allocate 109 GB and abort).
pub const MAX_DECODED_BYTES: u64 = 512 << 20;

/// Refuses an EXR whose data window, or tile, would decode to more than [`MAX_DECODED_BYTES`].
fn check_exr_size(path: &Path) -> anyhow::Result<()> {
    let meta = exr::meta::MetaData::read_from_file(path, false)
        .with_context(|| format!("cannot read image {}", path.display()))?;
    for (i, header) in meta.headers.iter().enumerate() {
        // Four bytes per sample at most (f32 or u32), per channel.
        let per_pixel = 4 * header.channels.list.len() as u64;
        let mut regions = vec![("data window", header.layer_size)];
        if let exr::meta::BlockDescription::Tiles(tiles) = &header.blocks {
            regions.push(("tile", tiles.tile_size));
        }
        for (what, size) in regions {
            let bytes = (size.width() as u64)
                .saturating_mul(size.height() as u64)
                .saturating_mul(per_pixel);
            if bytes > MAX_DECODED_BYTES {
                bail!(
                    "{}: layer {i}'s {what} is {}x{} pixels of {} channels ({bytes} bytes decoded); expected at most {} MiB per image",
                    path.display(),
                    size.width(),
                    size.height(),
                    header.channels.list.len(),
                    MAX_DECODED_BYTES >> 20
                );
            }
        }
    }
    Ok(())
}

/// Writes linear RGB clamped to [0, 1] as an 8-bit sRGB PNG.
pub fn write_png_srgb(image: &Image, path: impl AsRef<Path>) -> anyhow::Result<()> {
    let path = path.as_ref();
    let bytes: Vec<u8> = image
        .rgb
        .iter()
        .flat_map(|p| p.map(|c| (linear_to_srgb(c.clamp(0.0, 1.0)) * 255.0 + 0.5) as u8))
        .collect();
    let buf =
        ::image::RgbImage::from_raw(image.width, image.height, bytes).expect("buffer size matches");
    write_encoded(&buf, path).with_context(|| format!("cannot write PNG {}", path.display()))
}

/// An 8-bit image, in the format of `path`'s extension, through [`crate::atomic`].
pub(crate) fn write_encoded(buf: &::image::RgbImage, path: &Path) -> anyhow::Result<()> {
    let format = ::image::ImageFormat::from_path(path)?;
    let mut bytes = std::io::Cursor::new(Vec::new());
    buf.write_to(&mut bytes, format)?;
    crate::atomic::write_bytes(path, bytes.into_inner())
}

/// The pixels of an EXR file: RGB, or RGBA (a run's frames keep their alpha).
#[derive(Clone, Copy, Debug)]
pub enum ExrPixels<'a> {
    Rgb(&'a [[f32; 3]]),
    Rgba(&'a [[f32; 4]]),
}

/// Writes linear RGB as a 32-bit float EXR (see [`write_exr_pixels`]).
pub fn write_exr(image: &Image, path: impl AsRef<Path>) -> anyhow::Result<()> {
    write_exr_pixels(path.as_ref(), image.width, image.height, ExrPixels::Rgb(&image.rgb))
}

/// The workspace's one EXR writer: 32-bit floats in scan lines, ZIP compression, the most widely
/// readable layout (tinyexr, used by NVIDIA's FLIP tool, rejects tiled files). Written through
/// [`crate::atomic`].
pub fn write_exr_pixels(
    path: &Path,
    width: u32,
    height: u32,
    pixels: ExrPixels,
) -> anyhow::Result<()> {
    use exr::prelude::*;
    let (w, h) = (width as usize, height as usize);
    let len = match pixels {
        ExrPixels::Rgb(p) => p.len(),
        ExrPixels::Rgba(p) => p.len(),
    };
    anyhow::ensure!(len == w * h, "{}: image of {width}x{height} has {len} pixels", path.display());
    let encoding = Encoding {
        compression: Compression::ZIP16,
        blocks: Blocks::ScanLines,
        line_order: LineOrder::Increasing,
    };
    let mut bytes = std::io::Cursor::new(Vec::new());
    let encoded = match pixels {
        ExrPixels::Rgb(px) => {
            let channels = SpecificChannels::rgb(|Vec2(x, y): Vec2<usize>| {
                let p = px[y * w + x];
                (p[0], p[1], p[2])
            });
            exr::image::Image::from_encoded_channels((w, h), encoding, channels)
                .write()
                .to_buffered(&mut bytes)
        }
        ExrPixels::Rgba(px) => {
            let channels = SpecificChannels::rgba(|Vec2(x, y): Vec2<usize>| {
                let p = px[y * w + x];
                (p[0], p[1], p[2], p[3])
            });
            exr::image::Image::from_encoded_channels((w, h), encoding, channels)
                .write()
                .to_buffered(&mut bytes)
        }
    };
    encoded.with_context(|| format!("encoding EXR {}", path.display()))?;
    crate::atomic::write_bytes(path, bytes.into_inner())
        .with_context(|| format!("cannot write EXR {}", path.display()))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn srgb_round_trip() {
        for i in 0..=255 {
            let s = i as f32 / 255.0;
            assert!((linear_to_srgb(srgb_to_linear(s)) - s).abs() < 1e-5, "{s}");
        }
        assert!((srgb_to_linear(0.5) - 0.214_041_14).abs() < 1e-6);
    }

    #[test]
    fn png_and_exr_round_trip() {
        let tmp = tempfile::tempdir().unwrap();
        let dir = tmp.path().to_path_buf();
        std::fs::create_dir_all(&dir).unwrap();
        let img = Image::from_fn(7, 5, |x, y| [x as f32 / 6.0, y as f32 / 4.0, 0.25]);
        write_exr(&img, dir.join("a.exr")).unwrap();
        assert_eq!(load_image(dir.join("a.exr")).unwrap(), img);
        write_png_srgb(&img, dir.join("a.png")).unwrap();
        let back = load_image(dir.join("a.png")).unwrap();
        for (a, b) in img.rgb.iter().zip(&back.rgb) {
            for c in 0..3 {
                assert!((a[c] - b[c]).abs() < 0.01, "{a:?} {b:?}");
            }
        }
        let err = load_image(dir.join("a.jpg")).unwrap_err().to_string();
        assert!(err.contains("a.jpg") && err.contains(".png or .exr"), "{err}");
    }

    /// An EXR whose header claims a data window of 10^8 columns is refused before decoding, with
    /// the file and the size named (decoding it allocated 109 GB and aborted the process).
    #[test]
    fn an_exr_claiming_a_huge_data_window_is_refused() {
        let tmp = tempfile::tempdir().unwrap();
        let path = tmp.path().join("huge.exr");
        write_exr(&Image::from_fn(4, 4, |_, _| [0.5, 0.5, 0.5]), &path).unwrap();
        let mut bytes = std::fs::read(&path).unwrap();
        let key = b"dataWindow\0box2i\0";
        let at = bytes.windows(key.len()).position(|w| w == key).unwrap() + key.len() + 4;
        // box2i: xMin, yMin, xMax, yMax.
        bytes[at + 8..at + 12].copy_from_slice(&100_000_000i32.to_le_bytes());
        std::fs::write(&path, &bytes).unwrap();
        let err = load_image(&path).unwrap_err().to_string();
        assert!(err.contains("huge.exr") && err.contains("100000001x4 pixels"), "{err}");
    }

    /// A run's frames were written by `image`'s OpenEXR encoder (tiles) before they went through
    /// [`write_exr_pixels`] (scan lines): same pixels, bit for bit, in the layout NVIDIA's FLIP
    /// tool reads.
    #[test]
    fn rgba_in_scan_lines_has_the_pixels_of_the_tiled_encoder() {
        use ::image::ImageEncoder;
        use exr::prelude::*;
        let (w, h) = (67u32, 70u32); // more than one 64-pixel tile each way
        let px: Vec<[f32; 4]> = (0..w * h)
            .map(|i| {
                let v = (i as f32 * 0.37).sin() * 10f32.powi(i as i32 % 9 - 4);
                [v, -v, i as f32, [1.0, 0.0, 0.5, f32::INFINITY][i as usize % 4]]
            })
            .collect();
        let bytes: Vec<u8> = px.iter().flatten().flat_map(|v| v.to_ne_bytes()).collect();
        let mut tiled = std::io::Cursor::new(Vec::new());
        ::image::codecs::openexr::OpenExrEncoder::new(&mut tiled)
            .write_image(&bytes, w, h, ::image::ExtendedColorType::Rgba32F)
            .unwrap();
        let tmp = tempfile::tempdir().unwrap();
        let dir = tmp.path().to_path_buf();
        let path = dir.join("a.exr");
        write_exr_pixels(&path, w, h, ExrPixels::Rgba(&px)).unwrap();
        let scan_lines = std::fs::read(&path).unwrap();
        let layout = |bytes: &[u8]| {
            let meta = MetaData::read_from_buffered(std::io::Cursor::new(bytes), false).unwrap();
            meta.headers[0].blocks
        };
        assert!(matches!(layout(tiled.get_ref()), exr::meta::BlockDescription::Tiles(_)));
        assert_eq!(layout(&scan_lines), exr::meta::BlockDescription::ScanLines);
        let read = |bytes: Vec<u8>| -> Vec<[u32; 4]> {
            let image = read()
                .no_deep_data()
                .largest_resolution_level()
                .rgba_channels(
                    |size, _| (size.width(), vec![[0u32; 4]; size.area()]),
                    |(width, out), Vec2(x, y), (r, g, b, a): (f32, f32, f32, f32)| {
                        out[y * *width + x] = [r, g, b, a].map(f32::to_bits)
                    },
                )
                .first_valid_layer()
                .all_attributes()
                .from_buffered(std::io::Cursor::new(bytes))
                .unwrap();
            image.layer_data.channel_data.pixels.1
        };
        let expected: Vec<[u32; 4]> = px.iter().map(|p| p.map(f32::to_bits)).collect();
        assert_eq!(read(tiled.into_inner()), expected);
        assert_eq!(read(scan_lines), expected);
    }
}
