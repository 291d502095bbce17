//! Scenario playback over the frame crate's schedule (`playback`), the rendering methods'
//! registry (`methods`), resuming, interrupts, the manifest, the run's device memory and Mitsuba 3
//! as an independent renderer (`mitsuba`).

pub mod interrupt;
pub mod manifest;
pub mod memory;
pub mod methods;
pub mod mitsuba;
pub mod playback;
pub mod replayed_rows;
pub mod resume;
pub mod scenario;
