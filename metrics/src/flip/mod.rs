//! FLIP, the perceptual difference evaluator for alternating images (Andersson et al. 2020), and
//! its HDR extension (Andersson et al. 2021). See [`ldr`] for the pipeline, [`hdr`] for the
//! exposure scan.

pub mod color;
pub mod csf;
pub mod features;
pub mod hdr;
pub mod ldr;

use crate::image::Image;
pub use hdr::ExposureRange;

/// Pixels per degree of visual angle for an observer at `distance_m` from a monitor `width_m`
/// wide showing `width_px` pixels.
pub fn pixels_per_degree(distance_m: f32, width_px: f32, width_m: f32) -> f32 {
    distance_m * (width_px / width_m) * (std::f32::consts::PI / 180.0)
}

/// The papers' default viewing setup: 0.7 m from a 0.7 m wide 3840-pixel monitor (~67.02 ppd).
pub const DEFAULT_PPD: f32 = 0.7 * (3840.0 / 0.7) * (std::f32::consts::PI / 180.0);

#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize)]
pub struct Percentiles {
    pub p25: f32,
    pub p50: f32,
    pub p75: f32,
    pub p95: f32,
    pub p99: f32,
    pub max: f32,
}

impl Percentiles {
    /// Nearest-rank percentiles of a map (NaN-free).
    pub fn of(map: &[f32]) -> Self {
        if map.is_empty() {
            return Self { p25: 0.0, p50: 0.0, p75: 0.0, p95: 0.0, p99: 0.0, max: 0.0 };
        }
        let mut v = map.to_vec();
        v.sort_unstable_by(|a, b| a.total_cmp(b));
        let at = |q: f64| v[((q * v.len() as f64).ceil() as usize).clamp(1, v.len()) - 1];
        Self {
            p25: at(0.25),
            p50: at(0.5),
            p75: at(0.75),
            p95: at(0.95),
            p99: at(0.99),
            max: v[v.len() - 1],
        }
    }
}

#[derive(Clone, Debug)]
pub struct FlipResult {
    pub mean: f64,
    /// Per-pixel FLIP in [0, 1], row-major.
    pub map: Vec<f32>,
    pub percentiles: Percentiles,
    /// The exposures scanned (HDR-FLIP only).
    pub exposures: Option<ExposureRange>,
}

impl FlipResult {
    fn new(map: Vec<f32>, exposures: Option<ExposureRange>) -> Self {
        let mean = map.iter().map(|&v| v as f64).sum::<f64>() / map.len().max(1) as f64;
        Self { mean, percentiles: Percentiles::of(&map), map, exposures }
    }
}

/// LDR-FLIP of `test` against `reference`; both linear RGB, clamped to [0, 1].
pub fn flip_ldr(reference: &Image, test: &Image, ppd: f32) -> FlipResult {
    reference.assert_same_size(test, "flip_ldr");
    assert!(ppd > 0.0, "flip_ldr: pixels per degree must be positive, got {ppd}");
    let map = ldr::ldr_flip_map(
        &reference.rgb,
        &test.rgb,
        reference.width as usize,
        reference.height as usize,
        ppd,
    );
    FlipResult::new(map, None)
}

/// HDR-FLIP of `test` against `reference` (linear RGB, any non-negative range), with the
/// exposure range computed from the reference.
pub fn flip_hdr(reference: &Image, test: &Image, ppd: f32) -> FlipResult {
    let range = ExposureRange::from_reference(&reference.rgb);
    flip_hdr_with_range(reference, test, ppd, range)
}

/// HDR-FLIP with an explicit exposure range.
pub fn flip_hdr_with_range(
    reference: &Image,
    test: &Image,
    ppd: f32,
    range: ExposureRange,
) -> FlipResult {
    reference.assert_same_size(test, "flip_hdr");
    assert!(ppd > 0.0, "flip_hdr: pixels per degree must be positive, got {ppd}");
    assert!(
        range.count >= 2 && range.start <= range.stop,
        "flip_hdr: invalid exposure range {range:?}"
    );
    let map = hdr::hdr_flip_map(
        &reference.rgb,
        &test.rgb,
        reference.width as usize,
        reference.height as usize,
        ppd,
        &range,
    );
    FlipResult::new(map, Some(range))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn default_ppd() {
        assert!((DEFAULT_PPD - 67.0206).abs() < 1e-3);
        assert_eq!(pixels_per_degree(0.7, 3840.0, 0.7), DEFAULT_PPD);
    }

    #[test]
    fn identical_images_have_zero_error() {
        let a = Image::from_fn(32, 24, |x, y| [x as f32 / 31.0, y as f32 / 23.0, 0.3]);
        let r = flip_ldr(&a, &a, DEFAULT_PPD);
        assert!(r.mean.abs() < 1e-6 && r.percentiles.max < 1e-6);
        let h = Image::from_fn(32, 24, |x, y| [x as f32, y as f32 * 0.1, 4.0]);
        assert!(flip_hdr(&h, &h, DEFAULT_PPD).mean < 1e-6);
    }

    #[test]
    fn black_vs_white_is_near_maximal_and_monotone_in_difference() {
        let black = Image::filled(32, 32, [0.0; 3]);
        let white = Image::filled(32, 32, [1.0; 3]);
        let gray = Image::filled(32, 32, [0.2; 3]);
        let bw = flip_ldr(&black, &white, DEFAULT_PPD).mean;
        let bg = flip_ldr(&black, &gray, DEFAULT_PPD).mean;
        assert!(bw > 0.7 && bw <= 1.0, "{bw}");
        assert!(bg > 0.1 && bg < bw, "{bg} vs {bw}");
        // Green vs blue is the largest colour difference: error 1 in flat regions.
        let g = Image::filled(16, 16, [0.0, 1.0, 0.0]);
        let b = Image::filled(16, 16, [0.0, 0.0, 1.0]);
        assert!((flip_ldr(&g, &b, DEFAULT_PPD).mean - 1.0).abs() < 1e-4);
    }

    #[test]
    fn percentiles_nearest_rank() {
        let map: Vec<f32> = (1..=100).map(|i| i as f32).collect();
        let p = Percentiles::of(&map);
        assert_eq!((p.p25, p.p50, p.p95, p.p99, p.max), (25.0, 50.0, 95.0, 99.0, 100.0));
    }
}
