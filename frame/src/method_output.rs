//! What a method hands to the Measure and Record stages for one frame.

/// One rendered frame of a method.
#[derive(Clone, Debug, Default)]
pub struct MethodOutput {
    /// Linear HDR radiance, row-major, alpha = 1.
    pub radiance: Vec<[f32; 4]>,
    /// Per-pixel motion (pixels, current to previous), for reprojected SMAPE.
    pub motion: Vec<[f32; 2]>,
    /// Time per pass in execution order; `None` = not measured. Fill it with [`Self::timed`]
    /// from the passes' [`render::timing::PassTiming`]s.
    pub passes: Vec<(String, Option<f64>)>,
    /// The clock of `passes` (GPU timestamps or per-pass wall time); `None` = unknown.
    pub clock: Option<render::timing::Clock>,
    /// Rays traced this frame (camera + shadow + bounce, counted on the GPU); `None` = not
    /// reported.
    pub rays: Option<u64>,
    /// Paths shaded this frame; `None` = not reported.
    pub shaded: Option<u64>,
    /// Method-specific numbers for `frames.csv`, e.g. mean reliability or cache occupancy.
    pub stats: Vec<(String, f64)>,
    /// Method-specific images (linear RGB, or a false-colour map), written as
    /// `frames/METHOD/NAME/NNNN.png` (and `.exr` when `hdr`).
    pub images: Vec<MethodImage>,
}

impl MethodOutput {
    /// The common part of every method's output: image, motion, pass times and the counters.
    pub fn timed(
        radiance: Vec<[f32; 4]>,
        motion: Vec<[f32; 2]>,
        timings: &[render::timing::PassTiming],
        rays: u64,
        shaded: u64,
    ) -> Self {
        let mut output =
            Self { radiance, motion, rays: Some(rays), shaded: Some(shaded), ..Default::default() };
        output.add_timed(timings);
        output
    }

    /// Appends the times of passes run after the output was made (a method's Learn systems).
    pub fn add_timed(&mut self, timings: &[render::timing::PassTiming]) {
        self.passes.extend(timings.iter().map(|t| (t.pass.clone(), Some(t.ms))));
        self.clock = self.clock.or(timings.first().map(|t| t.clock));
    }
}

#[derive(Clone, Debug)]
pub struct MethodImage {
    pub name: String,
    pub pixels: Vec<[f32; 4]>,
    /// HDR images are written as EXR too and tone-mapped for the PNG; others are written as is.
    pub hdr: bool,
}
