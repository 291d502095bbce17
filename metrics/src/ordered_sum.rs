//! Parallel sums whose value does not depend on the thread count or on timing.
//!
//! rayon's `sum`/`reduce` combine partial results in an order set by adaptive splitting, which
//! changes with the number of threads and with work stealing; f64 addition is not associative, so
//! the last bits of a mean would differ between runs (a sweep run locally and as a Slurm array
//! merged to different numbers). Here the partials are taken over fixed chunks, in parallel, and
//! added in index order.

use rayon::prelude::*;

/// Items per parallel partial sum: large enough that task overhead stays small.
pub const CHUNK: usize = 4096;

/// Σ f(i) for i in 0..n, the same value for any thread count.
pub fn ordered_sum(n: usize, f: impl Fn(usize) -> f64 + Sync) -> f64 {
    let partials: Vec<f64> = (0..n.div_ceil(CHUNK))
        .into_par_iter()
        .map(|c| (c * CHUNK..((c + 1) * CHUNK).min(n)).map(&f).sum::<f64>())
        .collect();
    partials.iter().sum()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_same_sum_on_one_and_on_many_threads() {
        // Values spread over many magnitudes, so that a different association changes the sum.
        let items: Vec<f64> = (0..100_000u64)
            .map(|i| ((i * 2_654_435_761) % 1_000_003) as f64 * 10f64.powi((i % 17) as i32 - 8))
            .collect();
        let one = rayon::ThreadPoolBuilder::new()
            .num_threads(1)
            .build()
            .unwrap()
            .install(|| ordered_sum(items.len(), |i| items[i]));
        for threads in [2, 3, 8] {
            let many = rayon::ThreadPoolBuilder::new()
                .num_threads(threads)
                .build()
                .unwrap()
                .install(|| ordered_sum(items.len(), |i| items[i]));
            assert_eq!(one.to_bits(), many.to_bits(), "{threads} threads");
        }
        // And it is the sum: the sequential chunked order, to the bit.
        let sequential: f64 = items.chunks(CHUNK).map(|c| c.iter().sum::<f64>()).sum();
        assert_eq!(one.to_bits(), sequential.to_bits());
    }
}
