//! Density control (section 3.2), the decision of retrace.wgsl: how many samples a pixel adds or
//! purges given the mean visible-sample count of its 3x3 neighbourhood.

/// Positive: samples to add; negative: samples to purge; zero inside n_target ± δ.
pub fn adjustment(density: f32, n_target: f32, delta: f32) -> i32 {
    if density < n_target - delta {
        (n_target - density).ceil() as i32
    } else if density > n_target + delta {
        -((density - n_target).floor().max(1.0) as i32)
    } else {
        0
    }
}

#[cfg(test)]
mod tests {
    #[test]
    fn adds_below_purges_above_holds_inside() {
        use super::adjustment;
        assert_eq!(adjustment(0.0, 4.0, 1.0), 4);
        assert_eq!(adjustment(2.5, 4.0, 1.0), 2);
        assert_eq!(adjustment(3.0, 4.0, 1.0), 0);
        assert_eq!(adjustment(5.0, 4.0, 1.0), 0);
        assert_eq!(adjustment(5.2, 4.0, 1.0), -1);
        assert_eq!(adjustment(7.9, 4.0, 1.0), -3);
    }
}
