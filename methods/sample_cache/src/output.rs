//! What a frame reads back: its image, counters and times, and the whole cache for tests.

use crate::storage::GpuSlot;
use render::timing::PassTiming;

/// Counters of one frame (exact integers from the GPU's atomics).
#[derive(Clone, Debug, Default, PartialEq)]
pub struct CacheStats {
    pub shaded: u32,
    /// Primary-visibility rays: retraces and new samples (the rays of the paper's figure 7).
    pub rays: u32,
    /// Every ray of the frame: `rays` + the shadow and bounce rays of the shaded paths.
    pub all_rays: u32,
    pub new_samples: u32,
    pub purged: u32,
    pub reprojected: u32,
    pub dropped: u32,
    pub visible: u32,
    pub occupied: u32,
    /// Adaptive shading's samples shaded outside the importance budget: the base rate's, and
    /// the first of each pixel with no shaded visible sample.
    pub base_shaded: u32,
    pub slope_flagged: u32,
    /// Entries of the retrace list.
    pub retrace_listed: u32,
    /// The workgroups the GPU computed for the retrace and shade lists (indirect arguments).
    pub list_args: [[u32; 3]; 2],
    /// Importance bounds (w_min, w_max) of this frame's histogram buckets (last frame's).
    pub importance_bounds: (f32, f32),
    /// Histogram of the frame (adaptive shading), and the threshold bucket and coin chosen.
    pub histogram: Vec<u32>,
    pub threshold: u32,
    pub coin: f32,
}

/// One frame of the cache.
#[derive(Clone, Debug, Default)]
pub struct CacheFrame {
    pub radiance: Vec<[f32; 4]>,
    pub motion: Vec<[f32; 2]>,
    pub flags: Vec<u32>,
    pub stats: CacheStats,
    /// Per pass of [`PASSES`]: the sum of its dispatches.
    ///
    /// [`PASSES`]: crate::passes::PASSES
    pub timings: Vec<PassTiming>,
    /// Per dispatch of [`DISPATCHES`].
    ///
    /// [`DISPATCHES`]: crate::passes::DISPATCHES
    pub dispatch_timings: Vec<PassTiming>,
}

/// The whole cache as the last frame left it (tests, debugging).
#[derive(Clone, Debug)]
pub struct CacheState {
    pub masks: Vec<u32>,
    /// `slots * pixels`, layered: slot s of pixel p at `s * pixels + p`.
    pub slots: Vec<GpuSlot>,
}
