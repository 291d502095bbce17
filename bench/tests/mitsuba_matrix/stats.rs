//! Per-pixel agreement of two Monte Carlo images from their standard errors: Welch's t-test
//! per pixel, the count of pixels beyond a per-pixel level against its binomial law, and the
//! image mean. Every tolerance comes from the two estimates' own standard errors.

use statrs::distribution::{Binomial, ContinuousCDF, DiscreteCDF, Normal, StudentsT};

/// One pixel value of one renderer: its sample mean, the squared standard error of that mean
/// and the degrees of freedom of the variance estimate.
#[derive(Clone, Copy, Debug)]
pub struct Estimate {
    pub mean: f64,
    pub se2: f64,
    pub dof: f64,
}

/// The per-pixel level of the outlier count: a pixel is an outlier when its two-sided p-value
/// is below it. Under agreement the count is Binomial(pixels, OUTLIER_LEVEL).
pub const OUTLIER_LEVEL: f64 = 0.01;

/// One scene's three tests, each with its p-value.
#[derive(Debug)]
pub struct Verdict {
    pub pixels: usize,
    /// Bonferroni over the pixels: the smallest per-pixel p-value times the pixel count.
    pub p_max: f64,
    pub worst_t: f64,
    pub worst_pixel: usize,
    pub outliers: u64,
    pub expected_outliers: f64,
    /// P(Binomial >= outliers).
    pub p_count: f64,
    /// z of the difference of the image means (ours - Mitsuba) and its two-sided p-value.
    pub mean_z: f64,
    pub p_mean: f64,
    /// Relative difference of the image means.
    pub mean_rel: f64,
}

/// Two-sided p-value of Welch's t for one pixel; `float_se` is the rounding floor of the means
/// (both renderers sum in f32). A pixel without variance on either side (black, or an emitter
/// seen in full) agrees only when the values are equal to that floor.
fn pixel_p(a: Estimate, b: Estimate, float_se: f64) -> (f64, f64) {
    let se2 = a.se2 + b.se2 + float_se * float_se;
    let d = a.mean - b.mean;
    if se2 <= 0.0 {
        return (0.0, if d == 0.0 { 1.0 } else { 0.0 });
    }
    let t = d / se2.sqrt();
    // Welch-Satterthwaite degrees of freedom; the rounding term counts as exactly known.
    let denom = a.se2 * a.se2 / a.dof + b.se2 * b.se2 / b.dof;
    let dof = if denom > 0.0 { (se2 * se2 / denom).clamp(1.0, 1.0e6) } else { 1.0e6 };
    let p = 2.0 * StudentsT::new(0.0, 1.0, dof).expect("dof > 0").sf(t.abs());
    (t, p)
}

/// Compares the two images pixel by pixel; `float_rel` times a value is its rounding floor.
pub fn compare(ours: &[Estimate], theirs: &[Estimate], float_rel: f64) -> Verdict {
    assert_eq!(ours.len(), theirs.len());
    let n = ours.len();
    let (mut worst_p, mut worst_t, mut worst_pixel, mut outliers) = (1.0f64, 0.0f64, 0, 0u64);
    let (mut tested, mut sum_d, mut sum_se2, mut sum_b) = (0usize, 0.0, 0.0, 0.0);
    for i in 0..n {
        let (a, b) = (ours[i], theirs[i]);
        let float_se = float_rel * a.mean.abs().max(b.mean.abs());
        sum_d += a.mean - b.mean;
        sum_se2 += a.se2 + b.se2 + float_se * float_se;
        sum_b += b.mean;
        if a.se2 + b.se2 <= 0.0 && a.mean == b.mean {
            continue; // no variance and equal (black): no test
        }
        tested += 1;
        let (t, p) = pixel_p(a, b, float_se);
        if p < worst_p {
            (worst_p, worst_t, worst_pixel) = (p, t, i);
        }
        if p < OUTLIER_LEVEL {
            outliers += 1;
        }
    }
    let p_max = (worst_p * tested as f64).min(1.0);
    let p_count = if outliers == 0 {
        1.0
    } else {
        Binomial::new(OUTLIER_LEVEL, tested as u64).expect("valid").sf(outliers - 1)
    };
    // The image mean is a sum over hundreds of independent pixels: normal.
    let mean_z = if sum_se2 > 0.0 { sum_d / sum_se2.sqrt() } else { 0.0 };
    let p_mean = 2.0 * Normal::standard().sf(mean_z.abs());
    Verdict {
        pixels: tested,
        p_max,
        worst_t,
        worst_pixel,
        outliers,
        expected_outliers: OUTLIER_LEVEL * tested as f64,
        p_count,
        mean_z,
        p_mean,
        mean_rel: sum_d / sum_b.max(1e-12),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn agreeing_estimates_pass_and_a_shift_fails() {
        let e = |mean| Estimate { mean, se2: 0.01, dof: 1000.0 };
        let a: Vec<Estimate> =
            (0..256).map(|i| e(1.0 + 0.1 * ((i * 7919) % 13) as f64 / 13.0)).collect();
        let v = compare(&a, &a, 0.0);
        assert!(v.p_max >= 1.0 && v.outliers == 0 && v.p_mean > 0.99, "{v:?}");
        let b: Vec<Estimate> = a.iter().map(|x| e(x.mean + 1.0)).collect();
        let v = compare(&a, &b, 0.0);
        assert!(v.p_max < 1e-3 && v.p_count < 1e-3 && v.p_mean < 1e-3, "{v:?}");
    }
}
