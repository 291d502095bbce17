//! Order-independent sums of f32 values: each value is converted exactly (truncated below
//! 2^-48) to a 96-bit two's-complement fixed-point integer with 48 fractional bits, and integers
//! add associatively. On the GPU the 96 bits are three u32 words updated by atomicAdd with the
//! carries propagated by hand (shaders/fixed_sum.wgsl), so scattered sums (hash-grid gradients,
//! reliability-grid moments) are identical whatever the order the threads run in. This file is
//! the CPU mirror, bit for bit.

pub const FRACTION_BITS: u32 = 48;
/// Values with |x| >= 2^32 are refused (a sum of up to 2^15 of them cannot overflow 96 bits).
pub const MAX_MAGNITUDE: f32 = 4_294_967_296.0;

#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct FixedSum(i128);

impl FixedSum {
    /// Adds `x`. Returns false (and adds nothing) for a non-finite value or |x| >= 2^32.
    pub fn add(&mut self, x: f32) -> bool {
        if !x.is_finite() || x.abs() >= MAX_MAGNITUDE {
            return false;
        }
        // Exact: a 24-bit mantissa times a power of two fits an f64; trunc drops bits below 2^-48.
        let fixed = (x as f64 * (1u64 << FRACTION_BITS) as f64).trunc() as i128;
        self.0 = wrap96(self.0 + fixed);
        true
    }

    /// Adds `x` clamped to ±(2^32 - 2^8) (statistics, where a firefly must not void a step).
    /// Non-finite values are refused.
    pub fn add_clamped(&mut self, x: f32) -> bool {
        if !x.is_finite() {
            return false;
        }
        self.add(x.clamp(-MAX_CLAMPED, MAX_CLAMPED))
    }

    /// The three words as the GPU stores them: lo, mid, hi.
    pub fn words(&self) -> [u32; 3] {
        let v = self.0 as u128;
        [v as u32, (v >> 32) as u32, (v >> 64) as u32]
    }

    pub fn from_words(w: [u32; 3]) -> Self {
        let v = (w[0] as u128) | ((w[1] as u128) << 32) | ((w[2] as u128) << 64);
        FixedSum(wrap96(v as i128))
    }

    /// The sum as f32, computed exactly as the WGSL does: sign and magnitude, then
    /// f32(hi) * 2^16 + f32(mid) * 2^-16 + f32(lo) * 2^-48.
    pub fn to_f32(&self) -> f32 {
        let negative = self.0 < 0;
        let magnitude = FixedSum(wrap96(self.0.wrapping_neg()));
        let w = if negative { magnitude.words() } else { self.words() };
        let value = (w[2] as f32) * 65536.0
            + (w[1] as f32) * (1.0 / 65536.0)
            + (w[0] as f32) * f32::powi(2.0, -48);
        if negative { -value } else { value }
    }
}

/// Largest f32 below 2^32 (the clamp of statistics).
pub const MAX_CLAMPED: f32 = 4_294_967_040.0;

/// Sign-extends the low 96 bits.
fn wrap96(v: i128) -> i128 {
    (v << 32) >> 32
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn sums_are_exact_and_order_independent() {
        let values: Vec<f32> =
            (0..1000).map(|i| (i as f32 * 0.7319).sin() * 10f32.powi(i % 9 - 4)).collect();
        let mut forward = FixedSum::default();
        let mut backward = FixedSum::default();
        for &v in &values {
            assert!(forward.add(v));
        }
        for &v in values.iter().rev() {
            assert!(backward.add(v));
        }
        assert_eq!(forward, backward);
        let exact: f64 = values.iter().map(|&v| v as f64).sum();
        assert!(
            (forward.to_f32() as f64 - exact).abs() <= 1e-6 * exact.abs().max(1.0),
            "{} vs {exact}",
            forward.to_f32()
        );
    }

    #[test]
    fn negative_and_tiny_values_round_trip() {
        for x in [-1.0f32, -3.5e-9, 1e-14, -1e-14, 123456.78, -0.1, 2.0e9] {
            let mut s = FixedSum::default();
            assert!(s.add(x));
            let back = FixedSum::from_words(s.words());
            assert_eq!(back, s);
            let rel = ((back.to_f32() - x) / x).abs();
            assert!(
                rel < 1e-6 || (x.abs() < 1e-13 && (back.to_f32() - x).abs() < 4e-15),
                "{x} -> {}",
                back.to_f32()
            );
        }
        let mut s = FixedSum::default();
        assert!(!s.add(f32::NAN));
        assert!(!s.add(5e9));
        assert!(s.add_clamped(5e9));
        assert_eq!(s.to_f32(), MAX_CLAMPED);
    }
}
