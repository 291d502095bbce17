//! Slot reservation (listing 2, fixed), the CPU twin of `ssc_try_reserve` in reproject.wgsl:
//! one reservation after another, as the GPU's atomics serialise them.
//!
//! Listing 2 as printed leaves the loop with `break` after the first try, success or not, so a
//! sample that loses a race is dropped although free slots remain; the text says it retries.
//! Here a failed try ORs its bits into the local copy of the mask and the loop picks the next
//! candidate, ending on success or when no free slot remains.
//!
//! Listing 2 also lets a visible sample overwrite an invisible one in a full pixel. On the GPU
//! the visible samples reserve in a pass before the invisible ones instead ([`reserve_all`]),
//! which keeps the same samples without two threads ever writing one slot.

/// Reserves a free slot for a sample in `mask` (updated as `atomicOr` would, setting the
/// visibility bit for a visible sample); returns the slot index, lowest free first.
pub fn try_reserve(mask: &mut u32, n: u32, visible: bool) -> Option<u32> {
    let full = (1u32 << n) - 1;
    let mut m = *mask;
    loop {
        let candidates = !m & full;
        if candidates == 0 {
            return None;
        }
        let i = candidates.trailing_zeros();
        let o_bit = 1u32 << i;
        let s_val = o_bit | if visible { 1u32 << (i + n) } else { 0 };
        let previous = *mask;
        *mask |= s_val;
        m = previous | s_val;
        if previous & o_bit == 0 {
            return Some(i);
        }
    }
}

/// The two reservation passes over one pixel's incoming samples (`true` = visible): visible
/// samples first, then invisible ones into what is left. Returns the new mask and, per sample,
/// its slot (None: dropped).
pub fn reserve_all(samples: &[bool], n: u32) -> (u32, Vec<Option<u32>>) {
    let mut mask = 0;
    let mut slots = vec![None; samples.len()];
    for pass in [true, false] {
        for (k, &visible) in samples.iter().enumerate() {
            if visible == pass {
                slots[k] = try_reserve(&mut mask, n, visible);
            }
        }
    }
    (mask, slots)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn fills_free_slots_and_drops_when_full() {
        let n = 3;
        let mut m = 0;
        assert_eq!(try_reserve(&mut m, n, false), Some(0));
        assert_eq!(try_reserve(&mut m, n, true), Some(1));
        assert_eq!(try_reserve(&mut m, n, false), Some(2));
        assert_eq!(m, 0b010_111);
        assert_eq!(try_reserve(&mut m, n, false), None);
        assert_eq!(try_reserve(&mut m, n, true), None);
        assert_eq!(m, 0b010_111);
    }

    #[test]
    fn visible_samples_keep_their_slots_in_a_full_pixel() {
        // Listing 2's priority: 2 invisible samples arrive before 3 visible ones in a pixel of 3
        // slots; all 3 visible samples are kept, no invisible one, and no slot is written twice.
        let (mask, slots) = reserve_all(&[false, false, true, true, true], 3);
        assert_eq!(mask, 0b111_111);
        assert_eq!(slots, vec![None, None, Some(0), Some(1), Some(2)]);
        // With room for all, every sample keeps a slot of its own.
        let (mask, slots) = reserve_all(&[false, true, false, true], 5);
        assert_eq!(mask, 0b00011_01111);
        assert_eq!(slots, vec![Some(2), Some(0), Some(3), Some(1)]);
    }

    #[test]
    fn a_lost_race_retries_on_the_next_slot() {
        // The thread read an empty mask, but another thread took slot 0 meanwhile: the printed
        // listing would give up; the fixed loop lands in slot 1.
        let n = 4;
        let mut shared = 0b0001;
        let full = (1u32 << n) - 1;
        let stale = 0u32;
        let i = (!stale & full).trailing_zeros();
        assert_eq!(i, 0);
        assert_eq!(try_reserve(&mut shared, n, false), Some(1));
    }
}
