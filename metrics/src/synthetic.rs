//! Synthetic images: a deterministic hash and an HDR pair that looks rendered (the FLIP tests,
//! the report's tests and the image-metric bench).

use crate::image::Image;

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
