//! Memory a run holds: the device memory of its buffers and textures, from wgpu's allocator
//! report (where the backend has one: Vulkan and DX12), and the process's resident memory, from
//! /proc/self/status (Linux). A method's share is the difference of two [`device_bytes`] around
//! the building of its state ([`DeviceLedger`]).

use crate::gpu::Gpu;

/// Allocations wgpu makes for itself (staging, zero-initialisation) carry this label prefix;
/// they belong to no method.
const WGPU_INTERNAL: &str = "(wgpu internal)";

/// The live buffers and textures the run created itself (wgpu's own left out), by label and
/// size, after the device has finished everything submitted; `None` where the backend reports
/// no allocations.
pub fn allocations(gpu: &Gpu) -> Option<Vec<(String, u64)>> {
    // Flush the queue's pending writes and let finished submissions release their staging.
    gpu.queue.submit([]);
    gpu.device.poll(wgpu::PollType::wait_indefinitely()).ok()?;
    let report = gpu.device.generate_allocator_report()?;
    Some(
        report
            .allocations
            .into_iter()
            .filter(|a| !a.name.starts_with(WGPU_INTERNAL))
            .map(|a| (a.name, a.size))
            .collect(),
    )
}

/// Bytes of [`allocations`].
pub fn device_bytes(gpu: &Gpu) -> Option<u64> {
    allocations(gpu).map(|a| a.iter().map(|(_, size)| size).sum())
}

/// Allocations present in `after` and not in `before` (as multisets of label and size), summed
/// by label, largest first: what was built in between.
pub fn new_allocations(before: &[(String, u64)], after: &[(String, u64)]) -> Vec<(String, u64)> {
    let mut left: std::collections::HashMap<(&str, u64), usize> = Default::default();
    for (name, size) in before {
        *left.entry((name.as_str(), *size)).or_default() += 1;
    }
    let mut by_label: std::collections::BTreeMap<&str, u64> = Default::default();
    for (name, size) in after {
        match left.get_mut(&(name.as_str(), *size)) {
            Some(n) if *n > 0 => *n -= 1,
            _ => *by_label.entry(name.as_str()).or_default() += size,
        }
    }
    let mut rows: Vec<(String, u64)> =
        by_label.into_iter().map(|(n, s)| (n.to_string(), s)).collect();
    rows.sort_by(|a, b| b.1.cmp(&a.1).then_with(|| a.0.cmp(&b.0)));
    rows
}

/// Device memory the allocator has reserved in blocks (allocated or not), wgpu's own included.
pub fn device_reserved_bytes(gpu: &Gpu) -> Option<u64> {
    gpu.device.generate_allocator_report().map(|r| r.total_reserved_bytes)
}

/// The process's peak resident memory so far (VmHWM), bytes; `None` off Linux.
pub fn peak_resident_bytes() -> Option<u64> {
    status_kib("VmHWM:").map(|k| k * 1024)
}

/// Bytes the allocator has handed out and not taken back (glibc's `mallinfo2`: chunks in use in
/// every arena plus those it mapped on their own); `None` with another C library. Unlike
/// resident memory this falls when memory is freed: freed pages stay resident and later
/// allocations reuse them, so a leak can hide in resident memory for hundreds of frames.
#[cfg(all(target_os = "linux", target_env = "gnu"))]
pub fn heap_bytes() -> Option<u64> {
    // SAFETY: mallinfo2 takes no arguments and only reads the allocator's counters.
    let info = unsafe { libc::mallinfo2() };
    Some(info.uordblks as u64 + info.hblkhd as u64)
}

/// See the glibc version: no portable counter elsewhere.
#[cfg(not(all(target_os = "linux", target_env = "gnu")))]
pub fn heap_bytes() -> Option<u64> {
    None
}

/// The process's resident memory now (VmRSS), bytes; `None` off Linux.
pub fn resident_bytes() -> Option<u64> {
    status_kib("VmRSS:").map(|k| k * 1024)
}

/// A `NAME: N kB` line of /proc/self/status.
fn status_kib(name: &str) -> Option<u64> {
    let status = std::fs::read_to_string("/proc/self/status").ok()?;
    parse_status_kib(&status, name)
}

fn parse_status_kib(status: &str, name: &str) -> Option<u64> {
    let line = status.lines().find(|l| l.starts_with(name))?;
    let mut words = line[name.len()..].split_whitespace();
    let value = words.next()?.parse().ok()?;
    (words.next() == Some("kB")).then_some(value)
}

/// Device bytes attributed in turn: each [`Self::take`] returns what was allocated since the
/// previous one (the state built in between), `None` throughout where the backend has no
/// allocator report.
pub struct DeviceLedger {
    last: Option<Vec<(String, u64)>>,
}

impl DeviceLedger {
    /// Starts counting from what is allocated now.
    pub fn start(gpu: &Gpu) -> Self {
        Self { last: allocations(gpu) }
    }

    /// Bytes allocated since the last call (negative where state was released, as a
    /// difference of totals).
    pub fn take(&mut self, gpu: &Gpu) -> Option<i64> {
        self.take_buffers(gpu).map(|(delta, _)| delta)
    }

    /// Bytes allocated at the last call (or at the start), as counted then.
    pub fn total(&self) -> Option<u64> {
        self.last.as_ref().map(|a| a.iter().map(|(_, size)| size).sum())
    }

    /// As [`Self::take`], with the new allocations by label ([`new_allocations`]).
    pub fn take_buffers(&mut self, gpu: &Gpu) -> Option<(i64, Vec<(String, u64)>)> {
        let now = allocations(gpu);
        let result = match (&self.last, &now) {
            (Some(a), Some(b)) => {
                let total = |x: &[(String, u64)]| x.iter().map(|(_, s)| *s as i64).sum::<i64>();
                Some((total(b) - total(a), new_allocations(a, b)))
            }
            _ => None,
        };
        self.last = now;
        result
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn reads_kib_lines_of_proc_status() {
        let status = "Name:\tflicker\nVmPeak:\t  200 kB\nVmHWM:\t   1536 kB\nVmRSS:\t 1024 kB\n";
        assert_eq!(parse_status_kib(status, "VmHWM:"), Some(1536));
        assert_eq!(parse_status_kib(status, "VmRSS:"), Some(1024));
        assert_eq!(parse_status_kib(status, "VmSwap:"), None);
        assert_eq!(parse_status_kib("VmHWM:\t12 pages\n", "VmHWM:"), None);
        if cfg!(target_os = "linux") {
            // One snapshot: two reads would race the process's own growth in between.
            let status = std::fs::read_to_string("/proc/self/status").unwrap();
            let peak = parse_status_kib(&status, "VmHWM:").unwrap();
            let now = parse_status_kib(&status, "VmRSS:").unwrap();
            assert!(peak >= now && now > 0, "peak {peak}, now {now}");
        }
    }

    #[test]
    fn a_buffer_is_counted_once_and_released() {
        let gpu = Gpu::new().expect("a wgpu adapter (lavapipe on CI)");
        let mut ledger = DeviceLedger::start(&gpu);
        let buffer = gpu.device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("ledger test"),
            size: 1 << 20,
            usage: wgpu::BufferUsages::STORAGE,
            mapped_at_creation: false,
        });
        let grown = ledger.take(&gpu);
        // wgpu's Vulkan and DX12 backends report their allocations (CI runs Vulkan); where
        // none does, the ledger must say so rather than report zero.
        let reports =
            matches!(gpu.adapter.get_info().backend, wgpu::Backend::Vulkan | wgpu::Backend::Dx12);
        let Some(grown) = grown else {
            assert!(!reports, "{} has an allocator report, the ledger read none", gpu.summary);
            return;
        };
        assert!((1 << 20..(1 << 20) + 65536).contains(&grown), "{grown}");
        drop(buffer);
        assert_eq!(ledger.take(&gpu), Some(-grown));
    }

    #[test]
    fn new_allocations_are_a_multiset_difference_by_label() {
        let v = |rows: &[(&str, u64)]| -> Vec<(String, u64)> {
            rows.iter().map(|(n, s)| (n.to_string(), *s)).collect()
        };
        let before = v(&[("a", 4), ("b", 8), ("b", 8)]);
        let after = v(&[("b", 8), ("a", 4), ("b", 8), ("b", 8), ("c", 16), ("a", 2)]);
        // One more "b" of 8, a new "c", and an "a" of another size.
        assert_eq!(new_allocations(&before, &after), v(&[("c", 16), ("b", 8), ("a", 2)]));
        assert!(new_allocations(&after, &before).is_empty());
    }
}
