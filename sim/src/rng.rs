//! Seeded random numbers: SplitMix64 for streams, a stateless hash for per-frame draws.
//!
//! Everything random in the simulation goes through here so that a scenario's seed fixes
//! every frame.

/// Finalizer of SplitMix64: a good 64-bit mixing function.
pub fn mix64(mut z: u64) -> u64 {
    z = (z ^ (z >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
    z = (z ^ (z >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
    z ^ (z >> 31)
}

/// Uniform float in [0, 1) from a hash of (seed, stream, index), without state: a draw at
/// frame N does not depend on how many draws happened before.
pub fn hash_unit(seed: u64, stream: u64, index: u64) -> f32 {
    let h = mix64(mix64(mix64(seed) ^ stream) ^ index);
    (h >> 40) as f32 / (1u64 << 24) as f32
}

/// SplitMix64 generator.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Rng {
    state: u64,
}

impl Rng {
    pub fn new(seed: u64) -> Self {
        Self { state: mix64(seed ^ 0x5851_f42d_4c95_7f2d) }
    }

    /// An independent generator for a named purpose (e.g. one per flock).
    pub fn stream(seed: u64, stream: u64) -> Self {
        Self::new(mix64(seed) ^ mix64(stream.wrapping_add(1)))
    }

    pub fn next_u64(&mut self) -> u64 {
        self.state = self.state.wrapping_add(0x9e37_79b9_7f4a_7c15);
        mix64(self.state)
    }

    /// Uniform in [0, 1).
    pub fn next_f32(&mut self) -> f32 {
        (self.next_u64() >> 40) as f32 / (1u64 << 24) as f32
    }

    /// Uniform in [lo, hi).
    pub fn range(&mut self, lo: f32, hi: f32) -> f32 {
        lo + (hi - lo) * self.next_f32()
    }

    /// Uniform direction on the unit sphere.
    pub fn unit_vector(&mut self) -> glam::Vec3 {
        let z = self.range(-1.0, 1.0);
        let phi = self.range(0.0, std::f32::consts::TAU);
        let r = (1.0 - z * z).max(0.0).sqrt();
        glam::Vec3::new(r * phi.cos(), r * phi.sin(), z)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn streams_are_reproducible_and_distinct() {
        let a: Vec<u64> = (0..4).map({ let mut r = Rng::new(7); move |_| r.next_u64() }).collect();
        let b: Vec<u64> = (0..4).map({ let mut r = Rng::new(7); move |_| r.next_u64() }).collect();
        let c: Vec<u64> = (0..4).map({ let mut r = Rng::new(8); move |_| r.next_u64() }).collect();
        assert_eq!(a, b);
        assert_ne!(a, c);
        let mean = (0..10_000).map(|i| hash_unit(3, 1, i)).sum::<f32>() / 10_000.0;
        assert!((mean - 0.5).abs() < 0.02, "hash_unit mean {mean}");
    }
}
