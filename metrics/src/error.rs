//! Pixel-wise error against a reference: MSE, relative MSE and PSNR, averaged over pixels and
//! the three colour channels.

use crate::ordered_sum::ordered_sum;

use crate::image::Image;

/// ε of relative MSE's denominator, keeping black reference pixels finite.
pub const REL_MSE_EPS: f32 = 0.01;

fn mean_over_channels(
    reference: &Image,
    test: &Image,
    what: &str,
    f: impl Fn(f32, f32) -> f64 + Sync,
) -> f64 {
    reference.assert_same_size(test, what);
    let sum = ordered_sum(reference.len(), |i| {
        (0..3).map(|c| f(reference.rgb[i][c], test.rgb[i][c])).sum::<f64>()
    });
    sum / (3 * reference.len().max(1)) as f64
}

/// Mean squared error.
pub fn mse(reference: &Image, test: &Image) -> f64 {
    mean_over_channels(reference, test, "mse", |r, t| {
        let d = (t - r) as f64;
        d * d
    })
}

/// Relative MSE: (t - r)² / (r² + ε), the usual rendering error normalised by the signal.
pub fn relative_mse(reference: &Image, test: &Image) -> f64 {
    mean_over_channels(reference, test, "relative_mse", |r, t| {
        let d = (t - r) as f64;
        d * d / ((r as f64) * (r as f64) + REL_MSE_EPS as f64)
    })
}

/// PSNR in dB for a signal whose peak is `peak` (1 for LDR and for linear HDR measured against
/// display white). Identical images give +∞.
pub fn psnr_from_mse(mse: f64, peak: f64) -> f64 {
    10.0 * (peak * peak / mse).log10()
}

/// PSNR in dB with peak 1.
pub fn psnr(reference: &Image, test: &Image) -> f64 {
    psnr_from_mse(mse(reference, test), 1.0)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn analytic_values() {
        let r = Image::filled(10, 10, [0.5, 0.5, 0.0]);
        let t = Image::filled(10, 10, [0.6, 0.5, 0.3]);
        let expected = (0.01 + 0.0 + 0.09) / 3.0;
        assert!((mse(&r, &t) - expected).abs() < 1e-7);
        let rel = (0.01 / 0.26 + 0.0 + 0.09 / 0.01) / 3.0;
        assert!((relative_mse(&r, &t) - rel).abs() < 1e-5, "{}", relative_mse(&r, &t));
        assert!((psnr(&r, &t) - 10.0 * (1.0 / expected).log10()).abs() < 1e-4);
        assert!(psnr(&r, &r).is_infinite());
        // MSE 0.01 => 20 dB.
        assert!((psnr_from_mse(0.01, 1.0) - 20.0).abs() < 1e-9);
    }
}
