//! The hash table of the cache on the CPU, one insertion at a time: linear probing from the
//! home slot within `probe_limit` slots, last access per slot, eviction of slots not accessed
//! for more than `max_age` frames. Tests run it on the keys the GPU used and compare contents.

use super::key::{EMPTY, VoxelKey};

#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct CpuSlot {
    pub checksum: u32,
    /// Frame + 1 of the last access (0 = never).
    pub last_access: u32,
    pub home: u32,
}

#[derive(Clone, Debug)]
pub struct CpuHashTable {
    pub slots: Vec<CpuSlot>,
    pub probe_limit: u32,
    pub max_age: u32,
}

impl CpuHashTable {
    pub fn new(capacity: u32, probe_limit: u32, max_age: u32) -> Self {
        Self { slots: vec![CpuSlot::default(); capacity as usize], probe_limit, max_age }
    }

    fn capacity(&self) -> u32 {
        self.slots.len() as u32
    }

    /// Start of frame `frame` (stored as frame + 1 = `stamp`): evicts stale slots; returns
    /// (occupied after eviction, evicted).
    pub fn age(&mut self, stamp: u32) -> (u32, u32) {
        let (mut occupied, mut evicted) = (0, 0);
        for s in &mut self.slots {
            if s.checksum == EMPTY {
                continue;
            }
            if stamp - s.last_access > self.max_age {
                *s = CpuSlot::default();
                evicted += 1;
            } else {
                occupied += 1;
            }
        }
        (occupied, evicted)
    }

    /// Slot holding `key`, inserted into the first empty slot of its probe window if absent;
    /// `None` when the window is full of other keys. Marks the access with `stamp`.
    pub fn find_or_insert(&mut self, key: VoxelKey, stamp: u32) -> Option<u32> {
        let capacity = self.capacity();
        let window = move |i: u32| (key.home + i) % capacity;
        let slot = match self.find(key) {
            Some(s) => s,
            None => {
                let s = (0..self.probe_limit)
                    .map(window)
                    .find(|&s| self.slots[s as usize].checksum == EMPTY)?;
                self.slots[s as usize] =
                    CpuSlot { checksum: key.checksum, last_access: 0, home: key.home };
                s
            }
        };
        self.slots[slot as usize].last_access = stamp;
        Some(slot)
    }

    /// Slot holding `key`, without inserting.
    pub fn find(&self, key: VoxelKey) -> Option<u32> {
        (0..self.probe_limit)
            .map(|i| (key.home + i) % self.capacity())
            .find(|&s| self.slots[s as usize].checksum == key.checksum)
    }

    /// The occupied slots as (checksum, home, last access), sorted: what two tables holding the
    /// same keys agree on whatever the slots they landed in.
    pub fn contents(slots: impl IntoIterator<Item = CpuSlot>) -> Vec<(u32, u32, u32)> {
        let mut v: Vec<_> = slots
            .into_iter()
            .filter(|s| s.checksum != EMPTY)
            .map(|s| (s.checksum, s.home, s.last_access))
            .collect();
        v.sort_unstable();
        v
    }
}

/// Structural invariants of a table read back from the GPU (or this one): every key within
/// `probe_limit` of its home, no key twice. Returns a description of the first violation.
pub fn check_invariants(slots: &[CpuSlot], probe_limit: u32) -> Result<(), String> {
    let capacity = slots.len() as u32;
    let mut seen = std::collections::HashSet::new();
    for (i, s) in slots.iter().enumerate() {
        if s.checksum == EMPTY {
            continue;
        }
        let distance = (i as u32 + capacity - s.home) % capacity;
        if distance >= probe_limit {
            return Err(format!(
                "slot {i}: key {:#x} is {distance} slots from its home {} (probe limit {probe_limit})",
                s.checksum, s.home
            ));
        }
        if !seen.insert((s.checksum, s.home)) {
            return Err(format!("slot {i}: key {:#x} (home {}) stored twice", s.checksum, s.home));
        }
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn probing_eviction_and_reinsertion() {
        let mut t = CpuHashTable::new(8, 3, 2);
        let k = |home, checksum| VoxelKey { home, checksum };
        // Three keys with home 6 fill 6, 7, 0 (wrapping); a fourth does not fit.
        assert_eq!(t.find_or_insert(k(6, 10), 1), Some(6));
        assert_eq!(t.find_or_insert(k(6, 11), 1), Some(7));
        assert_eq!(t.find_or_insert(k(6, 12), 1), Some(0));
        assert_eq!(t.find_or_insert(k(6, 13), 1), None);
        assert_eq!(t.find_or_insert(k(6, 11), 2), Some(7));
        check_invariants(&t.slots, 3).unwrap();
        // Frame 4: key 10 and 12 (last access 1) are older than 2 frames, 11 (2) is not.
        assert_eq!(t.age(4), (1, 2));
        assert_eq!(t.find(k(6, 11)), Some(7));
        // A hole before 11 must not make a second copy of 11.
        assert_eq!(t.find_or_insert(k(6, 11), 4), Some(7));
        assert_eq!(t.find_or_insert(k(6, 13), 4), Some(6));
        check_invariants(&t.slots, 3).unwrap();
        let mut dup = t.slots.clone();
        dup[0] = dup[7];
        assert!(check_invariants(&dup, 3).is_err());
    }
}
