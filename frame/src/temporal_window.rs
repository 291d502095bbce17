//! Each method's effective temporal window (to compare methods at equal windows, or print
//! each method's window in the report): the number of frames of a box filter that averages
//! white per-frame noise down to the same variance as the method's temporal filter, 1 / Σ h_k²
//! of its normalised impulse response h over frames.
//!
//! Nominal: the filters' steady state (past the running-mean start), with no history rejected,
//! clamped or evicted; TAA's clamp and the caches' rejections shorten what a run achieves.
//! - An exponential blend of weight α per frame: (2 − α) / α frames (TAA: α = 0.1 → 19).
//! - The stable sample cache: each visible sample blends its shades with weight α (the settings'
//!   `alpha`; with App. C's roughness α_min, its diffuse bound 0.1, the longest), a pixel
//!   averages n_target visible samples, and `shading_rate` samples of it are shaded per frame:
//!   n_target · (2 − α) / α shades, shading_rate per frame (α 0.1: 4 · 19 = 76 frames). Its
//!   default, α = 0, is a running mean: no fixed window, none stated.
//! - The hash cache: each cell is updated once per frame with weight 1 / max_samples: 63 frames
//!   at 32.
//! - Under TAA, the two filters in series: each modelled as the exponential blend of its own
//!   window, the impulse responses convolved.

/// The window of an exponential blend of weight `alpha` per frame.
pub fn exponential(alpha: f64) -> f64 {
    (2.0 - alpha) / alpha
}

/// The per-frame blend weight whose exponential window is `window` frames.
fn weight_of(window: f64) -> f64 {
    2.0 / (window + 1.0)
}

/// The window of two filters in series (a method's, then TAA's), each the exponential blend of
/// its window: 1 / Σ h_k² of the convolved impulse responses.
pub fn in_series(a: f64, b: f64) -> f64 {
    let (wa, wb) = (weight_of(a), weight_of(b));
    // Truncated where both tails are below 1e-12 of their start.
    let len = ((-27.6 / (1.0 - wa).ln()).max(-27.6 / (1.0 - wb).ln()).ceil() as usize + 1).max(1);
    let ha: Vec<f64> = (0..len).map(|k| wa * (1.0 - wa).powi(k as i32)).collect();
    let hb: Vec<f64> = (0..len).map(|k| wb * (1.0 - wb).powi(k as i32)).collect();
    let h: Vec<f64> = (0..2 * len)
        .map(|n| (n.saturating_sub(len - 1)..=n.min(len - 1)).map(|k| ha[k] * hb[n - k]).sum())
        .collect();
    let total: f64 = h.iter().sum();
    total * total / h.iter().map(|v| v * v).sum::<f64>()
}

#[cfg(test)]
mod tests {
    use super::*;

    /// 1 / Σ h² of the exponential blend summed directly.
    fn direct(alpha: f64) -> f64 {
        1.0 / (0..100_000).map(|k| (alpha * (1.0 - alpha).powi(k)).powi(2)).sum::<f64>()
    }

    #[test]
    fn an_exponential_blend_has_the_closed_form_window() {
        for alpha in [1.0, 0.5, 0.1, 1.0 / 32.0] {
            assert!(
                (exponential(alpha) - direct(alpha)).abs() < 1e-6 * direct(alpha),
                "alpha {alpha}"
            );
        }
        assert_eq!(exponential(1.0), 1.0);
        assert!((weight_of(exponential(0.1)) - 0.1).abs() < 1e-12);
    }

    #[test]
    fn filters_in_series_lengthen_the_window() {
        // A one-frame filter changes nothing.
        assert!((in_series(1.0, 19.0) - 19.0).abs() < 1e-6);
        assert!((in_series(19.0, 1.0) - 19.0).abs() < 1e-6);
        // Two equal blends of weight a: Σh² = a^4 Σ (k+1)² b^{2k} = a^4 (1 + b²) / (1 − b²)³.
        let a: f64 = 0.1;
        let b2 = (1.0 - a).powi(2);
        let expected = (1.0 - b2).powi(3) / (a.powi(4) * (1.0 + b2));
        assert!(
            (in_series(19.0, 19.0) - expected).abs() < 1e-6 * expected,
            "{} vs {expected}",
            in_series(19.0, 19.0)
        );
        let (x, y) = (in_series(76.0, 19.0), in_series(19.0, 76.0));
        assert!((x - y).abs() < 1e-6 * x && x > 76.0, "{x} {y}");
    }
}
