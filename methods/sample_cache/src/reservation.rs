//! Slot reservation, the CPU twin of reproject.wgsl's `reserve_main` (`ssc_insert_key`) and
//! `gather_main`: which of the samples reprojected into a pixel it keeps, in which slots.
//!
//! Listing 2 reserves with an `atomicOr` race on the pixel's mask: in a pixel that more samples
//! reach than it has slots, the ones kept are those whose threads ran first, so two runs of the
//! same frames differ. Here each sample has a key (visible samples below invisible ones, listing
//! 2's priority; then the sample's index in last frame's cache, XOR a per-frame mask) and the
//! pixel keeps its N lowest keys, sorted, in N words: a thread carries its key down the words,
//! at each swapping it with a larger one it finds there (an atomic min) and carrying the larger
//! on, until an empty word takes it or it falls off the end (dropped). Word i receives every key
//! but the i lowest, whatever the interleaving, and keeps their minimum: the result is the same
//! for every order the threads run in ([`reserve`] takes the order as an argument to show it).
//! On the GPU the words hold the keys' complements and use `atomicMax`, so that the frame's
//! clear to 0 empties them.

/// Key bit of an invisible sample: every visible sample's key is lower.
pub const KEY_INVISIBLE: u32 = 0x8000_0000;
/// Bits of the sample's index (slot × pixels + pixel): 2^30 samples at most.
pub const KEY_INDEX: u32 = 0x3fff_ffff;

/// The reservation key of a sample: its visibility, then its index in last frame's cache XOR
/// the frame's mask (so that no source pixel or slot is preferred frame after frame).
pub fn key(visible: bool, index: u32, mask: u32) -> u32 {
    debug_assert!(index <= KEY_INDEX && mask <= KEY_INDEX);
    (if visible { 0 } else { KEY_INVISIBLE }) | ((index ^ mask) & KEY_INDEX)
}

/// One pixel's reservation of `keys` (distinct) into `n` slots, the threads' atomic steps
/// interleaved as `schedule` picks them: given the number of threads still carrying a key, it
/// returns which of them steps next. Returns the kept keys in slot order and the number
/// dropped.
pub fn reserve(
    keys: &[u32],
    n: usize,
    mut schedule: impl FnMut(usize) -> usize,
) -> (Vec<u32>, usize) {
    const EMPTY: u32 = u32::MAX;
    let mut words = vec![EMPTY; n];
    // (word index, carried key) of every thread still inserting.
    let mut carrying: Vec<(usize, u32)> = keys.iter().map(|&k| (0, k)).collect();
    let mut dropped = 0;
    while !carrying.is_empty() {
        let t = schedule(carrying.len()) % carrying.len();
        let (i, k) = carrying[t];
        // atomicMin: the word keeps the smaller, the thread carries the larger on.
        let previous = words[i];
        words[i] = previous.min(k);
        let larger = previous.max(k);
        if previous == EMPTY {
            carrying.swap_remove(t);
        } else if i + 1 == n {
            dropped += 1;
            carrying.swap_remove(t);
        } else {
            carrying[t] = (i + 1, larger);
        }
    }
    (words.into_iter().filter(|&w| w != EMPTY).collect(), dropped)
}

#[cfg(test)]
mod tests {
    use super::*;
    use render::scene::SplitMix64;

    /// The N lowest keys, sorted: what every interleaving must give.
    fn lowest(keys: &[u32], n: usize) -> Vec<u32> {
        let mut sorted = keys.to_vec();
        sorted.sort_unstable();
        sorted.truncate(n);
        sorted
    }

    #[test]
    fn every_interleaving_keeps_the_lowest_keys_in_order() {
        let mut rng = SplitMix64::new(11);
        for case in 0..500 {
            let n = 1 + (rng.next_u64() % 12) as usize;
            let count = (rng.next_u64() % 30) as usize;
            let mask = rng.next_u64() as u32 & KEY_INDEX;
            // Distinct sample indices, a third of them invisible.
            let mut indices: Vec<u32> = (0..200).collect();
            for i in (1..indices.len()).rev() {
                indices.swap(i, (rng.next_u64() % (i as u64 + 1)) as usize);
            }
            let keys: Vec<u32> = indices[..count]
                .iter()
                .map(|&i| key(!rng.next_u64().is_multiple_of(3), i, mask))
                .collect();
            let expected = lowest(&keys, n);
            for _ in 0..4 {
                let (kept, dropped) =
                    reserve(&keys, n, |threads| (rng.next_u64() % threads as u64) as usize);
                assert_eq!(kept, expected, "case {case}: n {n}, keys {keys:?}");
                assert_eq!(dropped, count.saturating_sub(n), "case {case}");
            }
        }
    }

    #[test]
    fn visible_samples_keep_their_slots_in_a_full_pixel() {
        // Listing 2's priority: 2 invisible samples arrive before 3 visible ones in a pixel of 3
        // slots; all 3 visible samples are kept, no invisible one.
        let keys =
            [key(false, 0, 0), key(false, 1, 0), key(true, 2, 0), key(true, 3, 0), key(true, 4, 0)];
        let (kept, dropped) = reserve(&keys, 3, |_| 0);
        assert_eq!(kept, vec![2, 3, 4]);
        assert_eq!(dropped, 2);
        // With room for all, every sample is kept, visible ones first.
        let (kept, dropped) = reserve(&keys[..4], 5, |t| t - 1);
        assert_eq!(kept, vec![2, 3, KEY_INVISIBLE, KEY_INVISIBLE | 1]);
        assert_eq!(dropped, 0);
    }

    #[test]
    fn the_mask_permutes_which_samples_a_full_pixel_keeps() {
        let keys = |mask| (0..8).map(|i| key(true, i, mask)).collect::<Vec<_>>();
        let kept = |mask| {
            let (kept, _) = reserve(&keys(mask), 3, |_| 0);
            kept.iter().map(|k| (k & KEY_INDEX) ^ mask).collect::<Vec<_>>()
        };
        assert_eq!(kept(0), vec![0, 1, 2]);
        assert_eq!(kept(5), vec![5, 4, 7]);
    }
}
