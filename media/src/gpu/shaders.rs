//! The media shader library: the generated structs, then the estimator files in dependency
//! order; a pass appends its bindings and entry points.

use render::gpu_struct::GpuStruct;

use super::medium::{MediumParams, RaySegment};

const FILES: [&str; 6] = [
    include_str!("../../shaders/media_rng.wgsl"),
    include_str!("../../shaders/media_grid.wgsl"),
    include_str!("../../shaders/media_dda.wgsl"),
    include_str!("../../shaders/media_tracking.wgsl"),
    include_str!("../../shaders/media_optical_depth.wgsl"),
    include_str!("../../shaders/media_estimators.wgsl"),
];

/// Structs, the medium's @group(0) declarations, the estimator library.
pub fn library() -> String {
    let mut s = String::new();
    s.push_str(MediumParams::WGSL);
    s.push_str(RaySegment::WGSL);
    s.push_str(&render::compute::declare(0, &super::medium::BINDINGS));
    for f in FILES {
        s.push_str(f);
    }
    s
}
