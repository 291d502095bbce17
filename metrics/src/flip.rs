//! FLIP, the perceptual difference evaluator for alternating images (Andersson et al. 2020), and
//! its HDR extension (Andersson et al. 2021), computed by the `flip-rs` crate (a port of NVIDIA
//! FLIP 1.7 whose maps equal NVIDIA's `flip-evaluator`'s; docs/lab/metrics-jod-flip.md). This file is the
//! adapter: our images in, our map, mean, percentiles and exposure range out.

use crate::image::{Image, linear_to_srgb};

/// Pixels per degree of visual angle for an observer at `distance_m` from a monitor `width_m`
/// wide showing `width_px` pixels.
pub fn pixels_per_degree(distance_m: f32, width_px: f32, width_m: f32) -> f32 {
    distance_m * (width_px / width_m) * (std::f32::consts::PI / 180.0)
}

/// The papers' default viewing setup: 0.7 m from a 0.7 m wide 3840-pixel monitor (~67.02 ppd).
pub const DEFAULT_PPD: f32 = flip_rs::DEFAULT_PPD;

/// ACES filmic curve fitted by a rational quadratic (Narkowicz 2015) with the fit's 0.6
/// pre-exposure folded in, as NVIDIA's FLIP tone-maps: coefficients of x², x, 1 of the
/// numerator and the denominator (flip-rs's `Tonemapper::Aces`).
const ACES_NUM: [f32; 3] = [0.6 * 0.6 * 2.51, 0.6 * 0.03, 0.0];
const ACES_DEN: [f32; 3] = [0.6 * 0.6 * 2.43, 0.6 * 0.59, 0.14];

/// Tone-mapped value at which the paper places both ends of the exposure range.
const TARGET: f32 = 0.85;

/// Luminance of linear sRGB (Rec. 709 weights).
fn luminance(p: [f32; 3]) -> f32 {
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
    /// per stop, at least two. Where the median is positive this is NVIDIA's automatic range
    /// bit for bit (the `exposure_range_is_nvidias` test); the two fallbacks below are ours.
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
        let mut lum: Vec<f32> = reference.iter().map(|&p| luminance(p)).collect();
        let y_max = lum.iter().copied().fold(f32::MIN, f32::max);
        let mid = lum.len() / 2;
        let (_, median, _) = lum.select_nth_unstable_by(mid, |a, b| a.total_cmp(b));
        let y_median = if *median > 0.0 {
            median.max(f32::EPSILON)
        } else {
            // More than half the image is black. NVIDIA takes f32::EPSILON as the median (some
            // 20 stops of black scanned); we take the smallest positive luminance, as the
            // hand-written FLIP did, so runs' FLIP values do not jump on dark scenes.
            lum.iter().copied().filter(|&l| l > 0.0).fold(f32::MAX, f32::min)
        };
        if y_max <= 0.0 || y_median == f32::MAX {
            // All-black reference (NVIDIA's tool exits): any exposure sees black.
            return Self { start: 0.0, stop: 1.0, count: 2 };
        }
        // In f64 as NVIDIA does, so that the range is the same bits.
        let start = f64::from(x_max / y_max).log2() as f32;
        let stop = f64::from(x_max / y_median).log2() as f32;
        // flip-rs evaluates at most MAX_EXPOSURES (128) exposures; a reference spanning more
        // stops than that is scanned more coarsely rather than refused.
        let count = ((stop - start).ceil().max(2.0) as usize).min(flip_rs::MAX_EXPOSURES);
        Self { start, stop, count }
    }

    pub fn exposures(&self) -> impl Iterator<Item = f32> + '_ {
        let step = (self.stop - self.start) / (self.count - 1) as f32;
        (0..self.count).map(move |i| self.start + i as f32 * step)
    }
}

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
    /// Mean of the map, summed in f64 (NVIDIA sums in f32; the difference is far below 1e-6).
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

fn finite(image: &Image) -> bool {
    image.rgb.iter().flatten().all(|c| c.is_finite())
}

/// flip-rs's interleaved RGB image of `image`, each channel through `f`.
fn interleaved(image: &Image, f: impl Fn(f32) -> f32) -> flip_rs::RgbImage<f32> {
    let pixels = image.rgb.iter().flatten().map(|&c| f(c)).collect();
    flip_rs::RgbImage::new(image.width as usize, image.height as usize, pixels)
        .unwrap_or_else(|e| panic!("FLIP of a {}x{} image: {e}", image.width, image.height))
}

/// A non-finite pixel leaves FLIP undefined (flip-rs refuses the pair): every pixel NaN, so the
/// run's FLIP shows NaN, rather than a panic in the middle of a run.
fn undefined(reference: &Image, exposures: Option<ExposureRange>) -> FlipResult {
    let n = reference.width as usize * reference.height as usize;
    FlipResult::new(vec![f32::NAN; n], exposures)
}

/// LDR-FLIP of `test` against `reference`; both linear RGB, clamped to [0, 1]. flip-rs reads
/// LDR images as sRGB (as NVIDIA's tool reads PNGs), so they are encoded here and decoded there.
pub fn flip_ldr(reference: &Image, test: &Image, ppd: f32) -> FlipResult {
    reference.assert_same_size(test, "flip_ldr");
    assert!(ppd > 0.0, "flip_ldr: pixels per degree must be positive, got {ppd}");
    if !(finite(reference) && finite(test)) {
        return undefined(reference, None);
    }
    let srgb = |c: f32| linear_to_srgb(c.clamp(0.0, 1.0));
    let map = flip_rs::ldr_flip(&interleaved(reference, srgb), &interleaved(test, srgb), ppd)
        .unwrap_or_else(|e| panic!("flip_ldr: {e}"));
    FlipResult::new(map.into_pixels(), None)
}

/// HDR-FLIP of `test` against `reference` (linear RGB, any non-negative range), with the
/// exposure range computed from the reference.
pub fn flip_hdr(reference: &Image, test: &Image, ppd: f32) -> FlipResult {
    reference.assert_same_size(test, "flip_hdr");
    if !(finite(reference) && finite(test)) {
        return undefined(reference, None);
    }
    let range = ExposureRange::from_reference(&reference.rgb);
    flip_hdr_with_range(reference, test, ppd, range)
}

/// HDR-FLIP with an explicit exposure range: ACES tone mapping at each exposure, the per-pixel
/// maximum of LDR-FLIP over them.
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
    if !(finite(reference) && finite(test)) {
        return undefined(reference, Some(range));
    }
    let mut options = flip_rs::HdrOptions::default();
    options.ppd = ppd;
    options.start_exposure = Some(range.start);
    options.stop_exposure = Some(range.stop);
    options.num_exposures = Some(range.count);
    options.tonemapper = flip_rs::Tonemapper::Aces;
    options.return_exposure_map = false;
    let linear = |c: f32| c;
    let result =
        flip_rs::hdr_flip(&interleaved(reference, linear), &interleaved(test, linear), options)
            .unwrap_or_else(|e| panic!("flip_hdr: {e}"));
    FlipResult::new(result.error_map.into_pixels(), Some(range))
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

    #[test]
    fn exposure_range_ends_tone_map_to_target() {
        let aces = |x: f32| {
            (x * x * ACES_NUM[0] + x * ACES_NUM[1] + ACES_NUM[2])
                / (x * x * ACES_DEN[0] + x * ACES_DEN[1] + ACES_DEN[2])
        };
        let img = vec![[0.1, 0.1, 0.1], [1.0, 1.0, 1.0], [8.0, 8.0, 8.0]];
        let r = ExposureRange::from_reference(&img);
        // Brightest (8) exposed by start and median (1) exposed by stop both tone-map to 0.85.
        assert!((aces(8.0 * 2f32.powf(r.start)) - TARGET).abs() < 1e-4);
        assert!((aces(1.0 * 2f32.powf(r.stop)) - TARGET).abs() < 1e-4);
        assert_eq!(r.count, 3); // 3 stops between 8 and 1
        let e: Vec<f32> = r.exposures().collect();
        assert!((e[0] - r.start).abs() < 1e-6 && (e[2] - r.stop).abs() < 1e-5);
    }

    #[test]
    fn exposure_range_is_nvidias() {
        // flip-rs left to choose the range itself does what NVIDIA's tool does. The noisy image
        // of each pair is the reference: its luminances are all distinct, so a wrong median
        // rank moves the stop exposure.
        for seed in 0..3 {
            let (clean, noisy) = crate::synthetic::synthetic_hdr_pair(40, 30, seed);
            let ours = ExposureRange::from_reference(&noisy.rgb);
            let mut options = flip_rs::HdrOptions::default();
            options.return_exposure_map = false;
            let image = |i: &Image| interleaved(i, |c| c);
            let p = flip_rs::hdr_flip(&image(&noisy), &image(&clean), options).unwrap().parameters;
            assert_eq!(
                (ours.start, ours.stop, ours.count),
                (p.start_exposure, p.stop_exposure, p.num_exposures)
            );
        }
    }

    #[test]
    fn dark_and_black_references_and_non_finite_pixels() {
        // Over half the pixels black: the stop exposure comes from the dimmest lit pixel.
        let dark = Image::from_fn(8, 8, |x, _| if x < 5 { [0.0; 3] } else { [0.5, 0.5, 0.5] });
        let r = ExposureRange::from_reference(&dark.rgb);
        assert!(r.stop - r.start < 1e-5 && r.count == 2, "{r:?}");
        let black = Image::filled(8, 8, [0.0; 3]);
        assert_eq!(flip_hdr(&black, &black, DEFAULT_PPD).mean, 0.0);
        let mut nan = dark.clone();
        nan.rgb[3] = [f32::NAN, 0.0, 0.0];
        let undefined = flip_hdr(&dark, &nan, DEFAULT_PPD);
        assert!(undefined.mean.is_nan() && undefined.percentiles.max.is_nan());
        assert!(flip_ldr(&dark, &nan, DEFAULT_PPD).mean.is_nan());
    }
}
