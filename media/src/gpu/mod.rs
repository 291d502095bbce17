//! The media estimators in WGSL (media/shaders/) and their GPU state: a medium's buffers
//! (`GpuMedium`), the transmittance image pass, and the volume and subsurface path passes. The
//! probes that run the estimators on given inputs for the GPU-vs-CPU tests live with those tests
//! (media/tests/probes/).

mod image_pass;
mod medium;
mod shaders;
mod specialised_pipeline;
mod subsurface_path_pass;
mod volume_path_pass;

pub use image_pass::{ImageParams, ImagePass, PASS};
pub use medium::{GpuMedium, MAX_MEDIA, MediumParams, RaySegment};
pub use shaders::{modules, modules_at, program};
pub use subsurface_path_pass::{
    MAX_EVENTS, SUBSURFACE_PATH_PASS, SubsurfacePathParams, SubsurfacePathPass, coefficient_table,
};
pub use volume_path_pass::{
    Combination, Eq9Transmittance, MediumOptics, MisWeight, ShadowTransmittance, VOLUME_PATH_PASS,
    VolumeImage, VolumePathParams, VolumePathPass, VolumePathSettings,
};
