//! Adaptive shading's dispatch decision (section 3.5), the CPU twin of shading_rate.wgsl: the
//! log-spaced importance buckets and the threshold that spends the budget.

/// Bucket of importance `w` among `m` log-spaced buckets over [lo, hi]; m - 1 = most important.
/// Degenerate bounds (no previous frame) put everything in the top bucket.
pub fn bucket(w: f32, lo: f32, hi: f32, m: u32) -> u32 {
    if !(lo > 0.0) || !(hi > lo) {
        return m - 1;
    }
    let f = (w / lo).ln() / (hi / lo).ln();
    (f * m as f32).floor().clamp(0.0, (m - 1) as f32) as u32
}

/// Walks the buckets from the most important down and returns the bucket where the running count
/// reaches `budget` and the probability with which its samples are dispatched, so that the
/// expected number dispatched is min(budget, total).
pub fn threshold(histogram: &[u32], budget: f32) -> (u32, f32) {
    let mut above = 0.0f32;
    for b in (0..histogram.len()).rev() {
        let c = histogram[b] as f32;
        if c > 0.0 && above + c >= budget {
            return (b as u32, (budget - above) / c);
        }
        above += c;
    }
    (0, 1.0)
}

/// Expected number of samples dispatched by [`threshold`].
pub fn expected_dispatch(histogram: &[u32], budget: f32) -> f32 {
    let (t, p) = threshold(histogram, budget);
    let above: u32 = histogram[t as usize + 1..].iter().sum();
    above as f32 + p * histogram[t as usize] as f32
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn buckets_are_log_spaced() {
        assert_eq!(bucket(1.0, 1.0 / 64.0, 1.0, 6), 5);
        assert_eq!(bucket(1.0 / 64.0, 1.0 / 64.0, 1.0, 6), 0);
        assert_eq!(bucket(1.0 / 8.0, 1.0 / 64.0, 1.0, 6), 3);
        assert_eq!(bucket(0.5, 0.0, 1.0, 13), 12);
    }

    #[test]
    fn threshold_spends_the_budget() {
        let h = [10, 0, 5, 20];
        assert_eq!(threshold(&h, 10.0), (3, 0.5));
        assert_eq!(threshold(&h, 22.0), (2, 0.4));
        assert_eq!(threshold(&h, 100.0), (0, 1.0));
        for budget in [0.0, 3.0, 20.0, 25.0, 31.0] {
            assert!((expected_dispatch(&h, budget) - budget).abs() < 1e-4, "{budget}");
        }
    }
}
