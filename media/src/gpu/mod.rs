//! The media estimators in WGSL (media/shaders/) and their GPU state: a medium's buffers
//! (`GpuMedium`) and the pass that runs one estimator on a list of segments with given seeds
//! (`EstimatorPass`, what the GPU-vs-CPU tests run); the closed-form MIS trials (`MisPass`).

mod closed_form_pass;
mod estimator_pass;
mod image_pass;
mod medium;
mod mis_pass;
mod shaders;
mod specialised_pipeline;
mod subsurface_path_pass;
mod trials;
mod volume_path_pass;

pub use closed_form_pass::{ClosedFormParams, ClosedFormPass};
pub use estimator_pass::{EstimatorPass, RayResult};
pub use image_pass::{ImageParams, ImagePass, PASS};
pub use medium::{GpuMedium, MAX_MEDIA, MediumParams, RaySegment};
pub use mis_pass::{MisParams, MisPass};
pub use shaders::{modules, modules_at, program};
pub use subsurface_path_pass::{
    MAX_EVENTS, SUBSURFACE_PATH_PASS, SubsurfacePathParams, SubsurfacePathPass, coefficient_table,
};
pub use volume_path_pass::{
    Combination, Eq9Transmittance, MediumOptics, MisWeight, ShadowTransmittance, VOLUME_PATH_PASS,
    VolumeImage, VolumePathParams, VolumePathPass, VolumePathSettings,
};
