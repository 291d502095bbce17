//! Slot reservation (listing 2, fixed), the CPU twin of `ssc_try_reserve` in reproject.wgsl:
//! one reservation after another, as the GPU's atomics serialise them.
//!
//! Listing 2 as printed leaves the loop with `break` after the first try, success or not, so a
//! sample that loses a race is dropped although free slots remain; the text says it retries.
//! Here a failed try ORs its bits into the local copy of the mask and the loop picks the next
//! candidate, ending on success or when no candidate remains.

/// Reserves a slot for a sample in `mask` (updated as `atomicOr` would); returns the slot index.
/// Candidates are unoccupied slots (lowest first) and, for a visible sample when the pixel is
/// full, occupied slots holding an invisible sample (it overwrites them).
pub fn try_reserve(mask: &mut u32, n: u32, visible: bool) -> Option<u32> {
    let full = (1u32 << n) - 1;
    let mut m = *mask;
    loop {
        let mut candidates = !m & full;
        if candidates == 0 && visible {
            candidates = m & !(m >> n) & full;
        }
        if candidates == 0 {
            return None;
        }
        let i = candidates.trailing_zeros();
        let (o_bit, v_bit) = (1u32 << i, 1u32 << (i + n));
        let s_val = o_bit | if visible { v_bit } else { 0 };
        let previous = *mask;
        *mask |= s_val;
        let success = previous & o_bit == 0 || (visible && previous & v_bit == 0);
        m = previous | s_val;
        if success {
            return Some(i);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn fills_free_slots_then_visible_overwrites_invisible() {
        let n = 3;
        let mut m = 0;
        assert_eq!(try_reserve(&mut m, n, false), Some(0));
        assert_eq!(try_reserve(&mut m, n, true), Some(1));
        assert_eq!(try_reserve(&mut m, n, false), Some(2));
        assert_eq!(m, 0b010_111);
        // Full: an invisible sample is dropped, a visible one takes the first invisible slot.
        assert_eq!(try_reserve(&mut m, n, false), None);
        assert_eq!(try_reserve(&mut m, n, true), Some(0));
        assert_eq!(try_reserve(&mut m, n, true), Some(2));
        assert_eq!(try_reserve(&mut m, n, true), None);
        assert_eq!(m, 0b111_111);
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
