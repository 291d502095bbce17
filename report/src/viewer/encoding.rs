//! What the viewer's page receives, as zlib-compressed byte planes (planes compress better than
//! interleaved bytes, and browsers inflate zlib natively with `DecompressionStream`):
//! - radiance as RGBE (Ward's shared-exponent format from the Radiance system): HDR in 4 bytes
//!   per pixel, decoded back to floats in the page for its exposure control;
//! - maps in [0, 1] (FLIP) as one byte per pixel;
//! - motion vectors as two i16 planes in 1/8 pixel.

use metrics::Image;

/// RGBE bytes of one linear RGB value: a mantissa per channel sharing the exponent of the
/// largest (Ward, Graphics Gems II "Real pixels"). Negative and non-finite values encode as 0.
pub fn encode_pixel(rgb: [f32; 3]) -> [u8; 4] {
    let c = rgb.map(|v| if v.is_finite() { v.max(0.0) } else { 0.0 });
    let v = c[0].max(c[1]).max(c[2]);
    if v < 1e-32 {
        return [0; 4];
    }
    // v = m * 2^e with m in [0.5, 1).
    let e = v.log2().floor() as i32 + 1;
    let e = e.clamp(-128, 127);
    let scale = 256.0 / 2f32.powi(e);
    let m = c.map(|x| (x * scale).min(255.0) as u8);
    [m[0], m[1], m[2], (e + 128) as u8]
}

/// The inverse of [`encode_pixel`] (the page's decoder does the same).
pub fn decode_pixel(b: [u8; 4]) -> [f32; 3] {
    if b[3] == 0 {
        return [0.0; 3];
    }
    let f = 2f32.powi(b[3] as i32 - 136);
    [b[0], b[1], b[2]].map(|m| (m as f32 + 0.5) * f)
}

/// The image as zlib-compressed planes R, G, B, E (width * height bytes each).
pub fn encode(img: &Image) -> Vec<u8> {
    let n = img.rgb.len();
    let mut planes = vec![0u8; 4 * n];
    for (i, &p) in img.rgb.iter().enumerate() {
        for (c, b) in encode_pixel(p).into_iter().enumerate() {
            planes[c * n + i] = b;
        }
    }
    zlib(&planes)
}

/// A per-pixel map in [0, 1] (e.g. FLIP) as zlib-compressed bytes, 255 = 1.
pub fn encode_map(map: &[f32]) -> Vec<u8> {
    let bytes: Vec<u8> = map.iter().map(|&v| (v.clamp(0.0, 1.0) * 255.0).round() as u8).collect();
    zlib(&bytes)
}

/// Steps of a pixel in which motion vectors are stored: eight per pixel, up to ±4095 pixels.
pub const MOTION_STEPS: f32 = 8.0;

/// Motion vectors (pixels) as zlib-compressed little-endian i16 planes dx, dy in 1/8 pixel.
pub fn encode_motion(img: &Image) -> Vec<u8> {
    let q = |v: f32| {
        if v.is_finite() { (v * MOTION_STEPS).round().clamp(-32767.0, 32767.0) as i16 } else { 0 }
    };
    let bytes: Vec<u8> =
        (0..2).flat_map(|c| img.rgb.iter().flat_map(move |p| q(p[c]).to_le_bytes())).collect();
    zlib(&bytes)
}

fn zlib(bytes: &[u8]) -> Vec<u8> {
    // Level 6: most of level 9's ratio on noisy radiance at a fraction of its time.
    miniz_oxide::deflate::compress_to_vec_zlib(bytes, 6)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn round_trip_keeps_about_eight_bits_of_the_largest_channel() {
        for rgb in [
            [1.0, 0.5, 0.25],
            [1e-4, 3e-4, 2e-4],
            [123.0, 0.0, 7.5],
            [0.999, 0.999, 0.999],
            [2.0, 2.0, 2.0],
        ] {
            let back = decode_pixel(encode_pixel(rgb));
            let max = rgb.iter().cloned().fold(0.0f32, f32::max);
            for c in 0..3 {
                assert!((back[c] - rgb[c]).abs() <= max / 128.0, "{rgb:?} -> {back:?}");
            }
        }
        assert_eq!(encode_pixel([0.0; 3]), [0; 4]);
        assert_eq!(encode_pixel([-1.0, f32::NAN, 0.0]), [0; 4]);
        // 1.0 = 0.5 * 2^1: mantissa 128, exponent byte 129.
        assert_eq!(encode_pixel([1.0, 0.0, 0.0]), [128, 0, 0, 129]);
    }

    #[test]
    fn planes_are_inflated_back() {
        let img = Image::from_fn(5, 3, |x, y| [x as f32, y as f32 * 0.1, 0.5]);
        let planes = miniz_oxide::inflate::decompress_to_vec_zlib(&encode(&img)).unwrap();
        assert_eq!(planes.len(), 4 * 15);
        let px = |i: usize| [planes[i], planes[15 + i], planes[30 + i], planes[45 + i]];
        assert_eq!(px(7), encode_pixel(img.rgb[7]));
        let map = miniz_oxide::inflate::decompress_to_vec_zlib(&encode_map(&[0.0, 0.5, 1.0, 2.0]))
            .unwrap();
        assert_eq!(map, [0, 128, 255, 255]);
        let motion = Image::new(2, 1, vec![[1.5, -0.25, 0.0], [-3.0, 10000.0, 0.0]]);
        let m = miniz_oxide::inflate::decompress_to_vec_zlib(&encode_motion(&motion)).unwrap();
        let i16s: Vec<i16> = m.chunks(2).map(|b| i16::from_le_bytes([b[0], b[1]])).collect();
        assert_eq!(i16s, [12, -24, -2, 32767]);
    }
}
