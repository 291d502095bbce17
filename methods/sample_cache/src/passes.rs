//! The cache's passes and dispatches, in frame order, and the list passes' workgroups.

/// Pass names in [`CacheFrame::timings`]: the stages of a frame, each one submission
/// ([`SampleCache::stage`]); the frame's systems run them in this order.
///
/// [`CacheFrame::timings`]: crate::output::CacheFrame::timings
/// [`SampleCache::stage`]: crate::cache::SampleCache::stage
pub const PASSES: [&str; 4] = ["reserve", "trace", "shade", "reconstruct"];

/// The dispatches (indices into [`DISPATCHES`]) of each of [`PASSES`].
pub(crate) const STAGE_DISPATCHES: [std::ops::Range<usize>; 4] = [0..4, 4..8, 8..12, 12..13];

/// The dispatches of a frame, `PASS/entry`, in order; each is timed on its own
/// ([`CacheFrame::dispatch_timings`]) and the pass time is the sum of its dispatches'.
///
/// [`CacheFrame::dispatch_timings`]: crate::output::CacheFrame::dispatch_timings
pub const DISPATCHES: [&str; 13] = [
    "reserve/begin_main",
    "reserve/reserve_main",
    "reserve/gather_main",
    "reserve/closest_main",
    "trace/retrace_main",
    "trace/retrace_args_main",
    "trace/retrace_list_main",
    "trace/finish_main",
    "shade/rates_main",
    "shade/select_main",
    "shade/shade_args_main",
    "shade/shade_main",
    "reconstruct/reconstruct_main",
];

/// Threads per workgroup of the list passes (`SSC_LIST_WORKGROUP` in storage.wgsl).
pub const LIST_WORKGROUP: u32 = 64;
/// WebGPU's guaranteed minimum of `max_compute_workgroups_per_dimension` (`SSC_MAX_GROUPS_X`).
pub const MAX_GROUPS_X: u32 = 65_535;

/// Workgroups `[x, y, 1]` of a list pass over `count` entries: x · y · LIST_WORKGROUP >= count
/// with x within every adapter's limit. The GPU's twin (list_dispatch.wgsl) writes the indirect
/// arguments; on the CPU this is the direct dispatch's worst case.
pub fn list_dispatch(count: u32) -> [u32; 3] {
    let groups = count.div_ceil(LIST_WORKGROUP);
    let x = groups.min(MAX_GROUPS_X);
    let y = if x > 0 { groups.div_ceil(x) } else { 0 };
    [x, y, 1]
}
