//! Stable sample cache (Philippi, Jensen & Frisvad 2025, "Stable Sample Caching for Interactive
//! Stereoscopic Ray Tracing", sections 3.1-3.5): a screen-space cache of N first-hit samples per
//! pixel, carried from frame to frame by forward reprojection, retraced sparsely, shaded
//! sparsely, and averaged into the image. See README.md in this folder for the map, and
//! docs/methods/sample-cache.md for the choices.
//!
//! Passes per frame (shaders/, one compute pass each, timed):
//! `reserve` (reproject.wgsl: begin_main, reserve_main, gather_main, closest_main), `trace` (retrace.wgsl: retrace_main,
//! list_dispatch.wgsl retrace_args_main, retrace.wgsl retrace_list_main, finish_main),
//! `shade` (shading_rate.wgsl rates_main + select_main, list_dispatch.wgsl shade_args_main,
//! shade.wgsl shade_main), `reconstruct` (reconstruct.wgsl).
//!
//! The two list passes (retrace_list_main, shade_main) are dispatched indirectly: one thread
//! per list entry, the workgroup counts written on the GPU by the args passes and copied into
//! an indirect buffer ([`SampleCache::set_indirect`] turns it off for comparisons: then N ·
//! pixels threads launch and those past the list's end exit).
//!
//! 64-bit atomics: the paper packs (closest depth, slope Δn) into one 64-bit atomicMin during
//! reprojection. WGSL core has only 32-bit atomics, so after the reservation one pass per pixel
//! (`gather_main`) writes the farthest visible depth of the samples the pixel kept, and another
//! (`closest_main`) the closest depth with its slope, both exact from the pixel's own samples; no
//! precision lost to packing; t_max of the 3x3 neighbours still costs one load each.
//!
//! Deterministic: the same scene, seed and settings give the same bits on any adapter. A pixel
//! keeps the N lowest reservation keys that reach it (`reservation.rs`), sorted by a chain of
//! atomics whose result does not depend on the order threads run in; every random number is
//! seeded by (seed, frame, pixel, slot); counters are integer atomics.

pub mod density;
pub mod reservation;
pub mod settings;
pub mod shading_rate;
pub mod slope;
pub mod storage;

mod cache;
mod gpu_types;
mod output;
mod passes;
mod program;

pub use cache::SampleCache;
pub use gpu_types::{FLAG_BASE, FLAG_HOLE, FLAG_SLOPE, GpuPixel, SscParams, SscPixel};
pub use output::{CacheFrame, CacheState, CacheStats};
pub use passes::{DISPATCHES, LIST_WORKGROUP, MAX_GROUPS_X, PASSES, list_dispatch};
pub use program::program;
pub use settings::{Retrace, SampleCacheSettings, ShadingMode};
pub use storage::{GpuSlot, SscSlot};

pub mod plugin;
pub mod recorded;
pub use plugin::Plugin;
