//! Sub-pixel jitter of the primary rays: the Halton (2, 3) sequence, the usual TAA choice
//! (low discrepancy in 2D for short cycles).

/// Radical inverse of `index` in `base`: the `index`-th Halton number in [0, 1).
pub fn halton(mut index: u32, base: u32) -> f32 {
    let mut f = 1.0f64;
    let mut r = 0.0f64;
    while index > 0 {
        f /= base as f64;
        r += f * (index % base) as f64;
        index /= base;
    }
    r as f32
}

/// Position of frame `frame`'s primary ray inside its pixel, in [0, 1)^2 (0.5 = centre).
/// Cycles through points 1..=`length` of Halton (2, 3) (point 0 is the corner (0, 0));
/// `length` 0 turns jitter off.
pub fn halton_jitter(frame: u32, length: u32) -> [f32; 2] {
    if length == 0 {
        return [0.5, 0.5];
    }
    let i = frame % length + 1;
    [halton(i, 2), halton(i, 3)]
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn halton_matches_radical_inverse() {
        assert_eq!(halton(1, 2), 0.5);
        assert_eq!(halton(2, 2), 0.25);
        assert_eq!(halton(3, 2), 0.75);
        assert!((halton(1, 3) - 1.0 / 3.0).abs() < 1e-7);
        assert!((halton(5, 3) - 7.0 / 9.0).abs() < 1e-7);
        assert_eq!(halton_jitter(0, 8), halton_jitter(8, 8));
        assert_eq!(halton_jitter(3, 0), [0.5, 0.5]);
    }

    #[test]
    fn a_cycle_covers_the_pixel_evenly() {
        // 16 points of Halton (2, 3): 3 to 5 in every quadrant, mean near the centre.
        let mut quadrants = [0; 4];
        let mut mean = [0.0; 2];
        for f in 0..16 {
            let [x, y] = halton_jitter(f, 16);
            assert!((0.0..1.0).contains(&x) && (0.0..1.0).contains(&y));
            quadrants[(x >= 0.5) as usize + 2 * (y >= 0.5) as usize] += 1;
            mean = [mean[0] + x / 16.0, mean[1] + y / 16.0];
        }
        assert!(quadrants.iter().all(|&q| (3..=5).contains(&q)), "{quadrants:?}");
        assert!((mean[0] - 0.5).abs() < 0.05 && (mean[1] - 0.5).abs() < 0.05, "{mean:?}");
    }
}
