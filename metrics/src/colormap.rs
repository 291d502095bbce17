//! The magma colour map (perceptually uniform, dark = no error), used for FLIP and SMAPE maps.

use std::path::Path;

use anyhow::Context;

/// Magma sampled at 17 evenly spaced points (sRGB-encoded display values), interpolated linearly.
const MAGMA_KEYS: [[f32; 3]; 17] = [
    [0.0015, 0.0005, 0.0139],
    [0.0396, 0.0311, 0.1335],
    [0.1131, 0.0655, 0.2768],
    [0.2117, 0.0620, 0.4186],
    [0.3167, 0.0717, 0.4854],
    [0.4147, 0.1104, 0.5047],
    [0.5128, 0.1482, 0.5076],
    [0.6136, 0.1818, 0.4985],
    [0.7164, 0.2150, 0.4753],
    [0.8169, 0.2559, 0.4365],
    [0.9043, 0.3196, 0.3881],
    [0.9609, 0.4183, 0.3596],
    [0.9867, 0.5356, 0.3822],
    [0.9961, 0.6537, 0.4462],
    [0.9969, 0.7696, 0.5349],
    [0.9924, 0.8843, 0.6401],
    [0.9871, 0.9914, 0.7495],
];

/// Magma colour of `v` in [0, 1] (clamped; NaN maps to 0), as 8-bit sRGB.
pub fn magma(v: f32) -> [u8; 3] {
    let v = if v.is_nan() { 0.0 } else { v.clamp(0.0, 1.0) };
    let pos = v * (MAGMA_KEYS.len() - 1) as f32;
    let i = (pos.floor() as usize).min(MAGMA_KEYS.len() - 2);
    let f = pos - i as f32;
    let (a, b) = (MAGMA_KEYS[i], MAGMA_KEYS[i + 1]);
    std::array::from_fn(|c| ((a[c] + (b[c] - a[c]) * f) * 255.0 + 0.5) as u8)
}

/// Magma-coloured RGB bytes of a map, `scale` dividing values first (1 for FLIP; e.g. 2 for SMAPE).
pub fn magma_bytes(map: &[f32], scale: f32) -> Vec<u8> {
    map.iter().flat_map(|&v| magma(v / scale)).collect()
}

/// Writes a per-pixel map in [0, 1] as a magma PNG.
pub fn write_map_png(
    map: &[f32],
    width: u32,
    height: u32,
    path: impl AsRef<Path>,
) -> anyhow::Result<()> {
    let path = path.as_ref();
    assert_eq!(map.len(), width as usize * height as usize, "map size must be width * height");
    let buf = ::image::RgbImage::from_raw(width, height, magma_bytes(map, 1.0))
        .expect("buffer size matches");
    crate::image::write_encoded(&buf, path)
        .with_context(|| format!("cannot write error map {}", path.display()))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn ends_and_monotone_lightness() {
        assert_eq!(magma(0.0), [0, 0, 4]);
        assert_eq!(magma(1.0), [252, 253, 191]);
        assert_eq!(magma(-1.0), magma(0.0));
        assert_eq!(magma(f32::NAN), magma(0.0));
        let luma = |c: [u8; 3]| 0.2126 * c[0] as f32 + 0.7152 * c[1] as f32 + 0.0722 * c[2] as f32;
        let mut last = -1.0;
        for i in 0..=100 {
            let l = luma(magma(i as f32 / 100.0));
            assert!(l >= last - 0.5, "magma must get lighter: {i}");
            last = l;
        }
    }
}
