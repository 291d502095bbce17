//! HDR-FLIP (Andersson et al. 2021): LDR-FLIP evaluated on tone-mapped exposures of both images
//! over an exposure range derived from the reference, keeping the per-pixel maximum.

use rayon::prelude::*;

use super::ldr::ldr_flip_map;

/// ACES filmic curve fitted by a rational quadratic (Narkowicz 2015), with the 0.6 pre-exposure
/// of that fit cancelled (so input 1 is not darkened): numerator and denominator coefficients
/// of x², x, 1.
const ACES_NUM: [f32; 3] = [0.6 * 0.6 * 2.51, 0.6 * 0.03, 0.0];
const ACES_DEN: [f32; 3] = [0.6 * 0.6 * 2.43, 0.6 * 0.59, 0.14];

/// Tone-mapped value at which the paper places both ends of the exposure range.
const TARGET: f32 = 0.85;

pub fn aces(x: f32) -> f32 {
    (x * x * ACES_NUM[0] + x * ACES_NUM[1] + ACES_NUM[2])
        / (x * x * ACES_DEN[0] + x * ACES_DEN[1] + ACES_DEN[2])
}

/// Luminance of linear sRGB (Rec. 709 weights).
pub fn luminance(p: [f32; 3]) -> f32 {
    0.2126 * p[0] + 0.7152 * p[1] + 0.0722 * p[2]
}

/// The exposure range HDR-FLIP scans, in stops (the image is multiplied by 2^exposure).
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize)]
pub struct ExposureRange {
    pub start: f32,
    pub stop: f32,
    pub count: usize,
}

impl ExposureRange {
    /// From the reference (2021 paper, §4): the start exposure maps the brightest luminance,
    /// and the stop exposure the median luminance, to the tone-mapped value 0.85; one exposure
    /// per stop, at least two.
    pub fn from_reference(reference: &[[f32; 3]]) -> Self {
        // x_max: the input the tone mapper maps to TARGET (larger root of num(x) = TARGET·den(x)).
        let a = ACES_NUM[0] - TARGET * ACES_DEN[0];
        let b = ACES_NUM[1] - TARGET * ACES_DEN[1];
        let c = ACES_NUM[2] - TARGET * ACES_DEN[2];
        let x_max = if a == 0.0 {
            -c / b
        } else {
            let d1 = -0.5 * (b / a);
            d1 + (d1 * d1 - c / a).sqrt()
        };
        let mut lum: Vec<f32> = reference.par_iter().map(|&p| luminance(p)).collect();
        let y_max = lum.iter().copied().fold(f32::MIN, f32::max);
        let mid = lum.len() / 2;
        let (_, median, _) = lum.select_nth_unstable_by(mid, |a, b| a.total_cmp(b));
        let mut y_median = *median;
        if y_median <= 0.0 {
            // More than half the image is black: fall back to the smallest positive luminance so
            // the range stays finite (the paper's formula would give an infinite stop exposure).
            y_median = lum.iter().copied().filter(|&l| l > 0.0).fold(f32::MAX, f32::min);
        }
        if y_max <= 0.0 || y_median == f32::MAX {
            // All-black reference: any exposure sees black; use a single 1-stop range around 0.
            return Self { start: 0.0, stop: 1.0, count: 2 };
        }
        let start = (x_max / y_max).log2();
        let stop = (x_max / y_median).log2();
        let count = (stop - start).ceil().max(2.0) as usize;
        Self { start, stop, count }
    }

    pub fn exposures(&self) -> impl Iterator<Item = f32> + '_ {
        let step = (self.stop - self.start) / (self.count - 1) as f32;
        (0..self.count).map(move |i| self.start + i as f32 * step)
    }
}

/// HDR-FLIP map: maximum over exposures of LDR-FLIP between the tone-mapped images.
pub fn hdr_flip_map(
    reference: &[[f32; 3]],
    test: &[[f32; 3]],
    width: usize,
    height: usize,
    ppd: f32,
    range: &ExposureRange,
) -> Vec<f32> {
    let mut out = vec![0.0f32; width * height];
    let tonemap = |img: &[[f32; 3]], scale: f32| -> Vec<[f32; 3]> {
        img.par_iter().map(|p| p.map(|c| aces(c * scale).clamp(0.0, 1.0))).collect()
    };
    for exposure in range.exposures() {
        let scale = 2.0f32.powf(exposure);
        let map =
            ldr_flip_map(&tonemap(reference, scale), &tonemap(test, scale), width, height, ppd);
        out.par_iter_mut().zip(map.par_iter()).for_each(|(o, &m)| *o = o.max(m));
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn aces_maps_range_ends_to_target() {
        assert_eq!(aces(0.0), 0.0);
        assert!(aces(1e6) > 0.99 && aces(1e6) <= 1.04);
        let img = vec![[0.1, 0.1, 0.1], [1.0, 1.0, 1.0], [8.0, 8.0, 8.0]];
        let r = ExposureRange::from_reference(&img);
        // Brightest (8) exposed by start and median (1) exposed by stop both tone-map to 0.85.
        assert!((aces(8.0 * 2f32.powf(r.start)) - TARGET).abs() < 1e-4);
        assert!((aces(1.0 * 2f32.powf(r.stop)) - TARGET).abs() < 1e-4);
        assert_eq!(r.count, 3); // 3 stops between 8 and 1
        let e: Vec<f32> = r.exposures().collect();
        assert!((e[0] - r.start).abs() < 1e-6 && (e[2] - r.stop).abs() < 1e-5);
    }
}
