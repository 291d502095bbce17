//! The frame as a bevy_ecs schedule (`frame`), the rendering methods as plugins (`methods`),
//! measurement, recording, and scenario playback.

pub mod frame;
pub mod frame_record;
pub mod manifest;
pub mod measure;
pub mod methods;
pub mod mitsuba;
pub mod output;
pub mod playback;
pub mod reference_cache;
pub mod run_folder;
pub mod scenario;
pub mod tonemap;
