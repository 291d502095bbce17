//! Scenario playback over the frame crate's schedule (`playback`), the rendering methods'
//! registry (`methods`), resuming, interrupts, the manifest and the run's device memory.

pub mod interrupt;
pub mod manifest;
pub mod memory;
pub mod methods;
pub mod playback;
pub mod replayed_rows;
pub mod resume;
pub mod scenario;
