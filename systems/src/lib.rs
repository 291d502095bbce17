//! The frame as a bevy_ecs schedule (`frame`), the rendering methods as plugins (`methods`),
//! measurement, recording, and scenario playback.

pub mod interrupt;
pub mod manifest;
pub mod memory;
pub mod methods;
pub mod mitsuba;
pub mod playback;
pub mod resume;
pub mod scenario;

/// The frame (its own crate, which knows no method) and what a run writes, under the names the
/// rest of this crate and its users know them by.
pub use ::frame;
pub use frame::frame_metrics as measure;
pub use frame::{frame_record, output, reference_cache, run_folder, tonemap};
