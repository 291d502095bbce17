//! Per-frame systems tying sim to render, and scenario playback.

pub mod bench;
pub mod extract;
pub mod frame_record;
pub mod manifest;
pub mod measure;
pub mod methods;
pub mod output;
pub mod playback;
pub mod reference_cache;
pub mod run_folder;
pub mod tonemap;
