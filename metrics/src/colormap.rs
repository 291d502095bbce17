//! The magma colour map (perceptually uniform, dark = no error), used for FLIP and SMAPE maps.

use std::path::Path;

use anyhow::Context;

/// Magma colour of `v` in [0, 1] (clamped; NaN maps to 0), as 8-bit sRGB: the nearest of the
/// 256 entries of FLIP's own map (`flip_rs::MAGMA`, NVIDIA FLIP's `MapMagma`), as FLIP picks it.
pub fn magma(v: f32) -> [u8; 3] {
    let v = if v.is_nan() { 0.0 } else { v.clamp(0.0, 1.0) };
    let entry = flip_rs::MAGMA[(v * 255.0 + 0.5) as usize];
    entry.map(|c| (c * 255.0 + 0.5) as u8)
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

    /// The colours FLIP itself gives a map (`ErrorMap::colorize`, as its PNGs store them).
    #[test]
    fn colours_of_flips_own_heat_map() {
        let values: Vec<f32> = (0..=1000).map(|i| i as f32 / 1000.0).collect();
        let map = flip_rs::ErrorMap::new(values.len(), 1, values.clone()).unwrap();
        let flip: Vec<u8> = map
            .colorize()
            .unwrap()
            .pixels()
            .iter()
            .map(|c| (c.clamp(0.0, 1.0) * 255.0 + 0.5) as u8)
            .collect();
        assert_eq!(magma_bytes(&values, 1.0), flip);
    }
}
