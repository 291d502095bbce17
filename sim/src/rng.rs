//! Seeded random numbers: SplitMix64 for streams, a stateless hash for per-frame draws.
//!
//! Everything random in the simulation goes through here so that a scenario's seed fixes
//! every frame.

pub use scene::{SplitMix64 as Rng, mix64};

/// Uniform float in [0, 1) from a hash of (seed, stream, index), without state: a draw at
/// frame N does not depend on how many draws happened before.
pub fn hash_unit(seed: u64, stream: u64, index: u64) -> f32 {
    let h = mix64(mix64(mix64(seed) ^ stream) ^ index);
    (h >> 40) as f32 / (1u64 << 24) as f32
}

/// An independent generator for a named purpose (e.g. one per flock).
pub fn stream(seed: u64, stream: u64) -> Rng {
    Rng::seeded(mix64(seed) ^ mix64(stream.wrapping_add(1)))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn streams_are_reproducible_and_distinct() {
        let a: Vec<u64> = (0..4)
            .map({
                let mut r = Rng::seeded(7);
                move |_| r.next_u64()
            })
            .collect();
        let b: Vec<u64> = (0..4)
            .map({
                let mut r = Rng::seeded(7);
                move |_| r.next_u64()
            })
            .collect();
        let c: Vec<u64> = (0..4)
            .map({
                let mut r = Rng::seeded(8);
                move |_| r.next_u64()
            })
            .collect();
        assert_eq!(a, b);
        assert_ne!(a, c);
        let mean = (0..10_000).map(|i| hash_unit(3, 1, i)).sum::<f32>() / 10_000.0;
        assert!((mean - 0.5).abs() < 0.02, "hash_unit mean {mean}");
    }
}
