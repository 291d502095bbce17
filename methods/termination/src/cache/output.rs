//! A frame's read-back.

use super::statistics::{CacheStatistics, TerminationStats};
use render::timing::PassTiming;

#[derive(Clone, Debug, Default)]
pub struct TerminationOutput {
    pub radiance: Vec<[f32; 4]>,
    pub motion: Vec<[f32; 2]>,
    /// Surface vertices of each pixel's path, the vertex after a blend counting α (the paper's
    /// Fig. 11 image).
    pub path_length: Vec<f32>,
    /// Mean vertices per path.
    pub mean_path_length: f64,
    pub stats: TerminationStats,
    /// The records after this frame's passes.
    pub cache: CacheStatistics,
    pub timings: Vec<PassTiming>,
    pub rays: u64,
    /// One path per pixel plus the propagated vertices.
    pub shaded: u64,
}
