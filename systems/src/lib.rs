//! Per-frame systems tying sim to render, and scenario playback.

pub mod frame_record;
pub mod manifest;
pub mod output;
pub mod playback;
pub mod reference_cache;
pub mod run_folder;
pub mod tonemap;
