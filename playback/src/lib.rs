//! Scenario playback over the frame crate's schedule (`play`), the rendering methods' registry
//! (`methods`), resuming, interrupts, the manifest and the run's memory.

pub mod interrupt;
pub mod manifest;
pub mod memory;
pub mod methods;
pub mod play;
pub mod replayed_rows;
pub mod resume;
pub mod scenario;
