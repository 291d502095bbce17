//! Density control (section 3.2), the decision of retrace.wgsl: how many samples a pixel adds or
//! purges. The paper acts when the mean visible-sample count of the 3x3 neighbourhood leaves
//! n_target ± δ, adding or purging samples, but does not say how many; here the pixel moves its
//! own visible count to n_target, at least one sample either way (one sample per frame converged
//! too slowly after a zoom-out crowded some pixels with 8-12 samples). A pixel whose own count
//! exceeds n_target + δ also purges when its neighbourhood is within bounds: otherwise a crowded
//! pixel next to sparse ones (whose last visible sample cannot go) keeps their neighbourhoods
//! above the bound for ever.

/// Positive: samples to add; negative: visible samples to purge (the count is of visible samples,
/// so retrace.wgsl purges among them, never the last one); zero inside n_target ± δ.
pub fn adjustment(density: f32, own_visible: u32, n_target: f32, delta: f32) -> i32 {
    let own = own_visible as f32;
    if density < n_target - delta {
        (n_target.round() - own).max(1.0) as i32
    } else if density > n_target + delta || own > n_target + delta {
        -((own - n_target.round()).max(1.0) as i32)
    } else {
        0
    }
}

#[cfg(test)]
mod tests {
    #[test]
    fn adds_below_purges_above_holds_inside() {
        use super::adjustment;
        assert_eq!(adjustment(0.0, 0, 4.0, 1.0), 4);
        assert_eq!(adjustment(2.5, 1, 4.0, 1.0), 3);
        assert_eq!(adjustment(2.5, 6, 4.0, 1.0), 1);
        assert_eq!(adjustment(3.0, 0, 4.0, 1.0), 0);
        assert_eq!(adjustment(5.0, 5, 4.0, 1.0), 0);
        assert_eq!(adjustment(4.0, 12, 4.0, 1.0), -8);
        assert_eq!(adjustment(5.2, 12, 4.0, 1.0), -8);
        assert_eq!(adjustment(7.9, 2, 4.0, 1.0), -1);
    }
}
