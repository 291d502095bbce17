//! Rendering methods as per-frame systems: the playback loop asks each method for one frame, in
//! the scenario's order, after the scene has been updated. A method owns its own GPU state
//! (caches, histories) and may use the shared path tracer (scene geometry, G-buffer).

pub mod nirc;
mod path_tracing;
mod sample_cache;
mod hash_cache;
mod taa;

use anyhow::Result;
use render::gpu::Gpu;
use render::path_tracer::PathTracer;
use render::scene::SceneDesc;
use sim::{MethodSpec, Scenario};

pub use nirc::Nirc;
pub use path_tracing::PathTracing;
pub use sample_cache::SampleCacheMethod;
pub use hash_cache::HashCacheMethod;
pub use taa::TaaMethod;

/// Everything a method may read while rendering one frame.
pub struct FrameContext<'a> {
    pub gpu: &'a Gpu,
    /// Shared path tracer, already updated to this frame's scene.
    pub tracer: &'a mut PathTracer,
    pub scene: &'a SceneDesc,
    pub scenario: &'a Scenario,
    /// Simulation frame (warm-up frames included), the seed of per-frame randomness.
    pub frame: u32,
    /// False during warm-up: the frame is rendered (caches learn) but not recorded.
    pub recorded: bool,
    /// The run's cache folder (`--cache-dir`): references, and state a method may reuse
    /// across runs (NIRC warm starts).
    pub cache_dir: &'a std::path::Path,
}

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
    pub fn timed(radiance: Vec<[f32; 4]>, motion: Vec<[f32; 2]>, timings: &[render::timing::PassTiming], rays: u64, shaded: u64) -> Self {
        Self {
            radiance,
            motion,
            passes: timings.iter().map(|t| (t.pass.clone(), Some(t.ms))).collect(),
            clock: timings.first().map(|t| t.clock),
            rays: Some(rays),
            shaded: Some(shaded),
            ..Default::default()
        }
    }
}

#[derive(Clone, Debug)]
pub struct MethodImage {
    pub name: String,
    pub pixels: Vec<[f32; 4]>,
    /// HDR images are written as EXR too and tone-mapped for the PNG; others are written as is.
    pub hdr: bool,
}

pub trait FrameMethod {
    /// Folder and table name, e.g. `pt_4spp`.
    fn label(&self) -> String;
    /// Samples per pixel it spends per frame (for equal-budget comparisons).
    fn spp(&self) -> u32;
    fn render(&mut self, ctx: &mut FrameContext) -> Result<MethodOutput>;
}

/// Builds the method a scenario asks for.
pub fn build(spec: &MethodSpec, _gpu: &Gpu, _scenario: &Scenario, _scene: &SceneDesc) -> Result<Box<dyn FrameMethod>> {
    Ok(match spec {
        MethodSpec::PathTracing { spp } => Box::new(PathTracing::new(*spp)),
        MethodSpec::Nirc { spp, predictor, cache, paths, pretrain_frames } => Box::new(Nirc::new(
            _scenario,
            nirc::NircSettings { spp: *spp, cache: cache.clone(), paths: paths.clone(), pretrain_frames: *pretrain_frames },
            *predictor,
        )?),
        MethodSpec::SampleCache { .. } => {
            let settings = spec.sample_cache_settings().expect("a SampleCache spec");
            settings.validate().map_err(|e| anyhow::anyhow!("{}: SampleCache: {e}", _scenario.origin.display()))?;
            Box::new(SampleCacheMethod::new(settings))
        }
        MethodSpec::Taa { alpha, clamp, jitter_length, depth_tolerance, normal_threshold } => Box::new(TaaMethod::new(render::taa::TaaSettings {
            alpha: *alpha,
            clamp: *clamp,
            jitter_length: *jitter_length,
            depth_tolerance: *depth_tolerance,
            normal_threshold: *normal_threshold,
            ..Default::default()
        })?),
        MethodSpec::HashCache { capacity, probe_limit, max_age, lod_scale, normal_lod, jitter, lookup, max_samples, taa } => {
            let settings = render::hash_cache::HashCacheSettings {
                capacity: *capacity,
                probe_limit: *probe_limit,
                max_age: *max_age,
                lod_scale: *lod_scale,
                normal_lod: *normal_lod,
                jitter: *jitter,
                lookup: *lookup,
                max_samples: *max_samples,
                ..Default::default()
            };
            let taa = taa.then(render::taa::TaaSettings::default);
            Box::new(HashCacheMethod::new(settings, taa, spec.label())?)
        }
    })
}
