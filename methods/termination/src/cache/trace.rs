//! The image: a tracer's trace over the folded records and the frame's read-back.

use super::passes::TcPass;
use super::statistics::{CacheStatistics, TRACE_COUNTERS, stats_of};
use super::{TerminationCache, TerminationOutput, TerminationTracer};
use crate::rule::TerminationRule;
use crate::settings::RadianceScale;
use render::error::RenderError;
use render::gpu::Gpu;
use render::readback::copy_all;
use render::scene_gpu::SceneGpu;
use render::timing::PassTiming;
use taa::TaaPrimary;

impl TerminationCache {
    /// The frame's image by the cache's own tracer (its settings' rule): [`Self::trace_with`].
    pub fn trace(
        &self,
        gpu: &Gpu,
        scene: &SceneGpu,
        updated: Vec<PassTiming>,
    ) -> Result<TerminationOutput, RenderError> {
        self.trace_with(gpu, scene, &self.own, updated)
    }

    /// The frame's image by `tracer` after [`Self::update`] (`updated`: times reported first,
    /// empty for a tracer that does not report the cache's passes): the tracer with its rule's
    /// decision over the folded records, and the frame's read-back. Its output is what the
    /// tracer's rule gives alone: its image and trace counters with the cache's counts
    /// (propagated vertices and rays, records).
    pub fn trace_with(
        &self,
        gpu: &Gpu,
        scene: &SceneGpu,
        tracer: &TerminationTracer,
        updated: Vec<PassTiming>,
    ) -> Result<TerminationOutput, RenderError> {
        let absolute = matches!(
            tracer.settings.rule,
            TerminationRule::VarianceBounding { relative: false, .. }
        );
        if absolute && tracer.settings.radiance_scale == RadianceScale::CacheMean {
            let unit = self.radiance_unit(&tracer.settings);
            if !(unit > 0.0 && unit.is_finite()) {
                return Err(RenderError::Settings(format!(
                    "Termination radiance_scale CacheMean: the cache's mean radiance is {unit} after {} warm-up frames (no filled record to derive the unit from); use more warmup_frames or radiance_scale: Stated",
                    self.settings.warmup_frames
                )));
            }
        }
        // The frame's parameters with the tracer's rule; its trace counters cleared (the
        // cache's words of the own tracer's counters are the frame's so far).
        let tc = self.params(&tracer.settings, self.frame_params, tracer.offers);
        gpu.queue.write_buffer(&tracer.tc, 0, bytemuck::bytes_of(&tc));
        for word in TRACE_COUNTERS {
            gpu.queue.write_buffer(&tracer.counters, word * 4, &[0u8; 4]);
        }
        let mut timings = updated;
        timings.extend(self.submit(gpu, scene, &tracer.timer, &[TcPass::Trace], &tracer.group)?);
        let [colour, primary, path_length, traced, counters] = copy_all(
            gpu,
            [
                (&tracer.colour, "termination colour"),
                (&tracer.primary, "termination primary hits"),
                (&tracer.path_length, "termination path length"),
                (&tracer.counters, "termination trace counters"),
                (&self.own.counters, "termination counters"),
            ],
        );
        let radiance = colour.read(gpu)?;
        let primary: Vec<TaaPrimary> = primary.read(gpu)?;
        let path_length: Vec<f32> = path_length.read(gpu)?;
        let mut words: Vec<u32> = counters.read(gpu)?;
        let traced: Vec<u32> = traced.read(gpu)?;
        for word in TRACE_COUNTERS {
            words[word as usize] = traced[word as usize];
        }
        let stats = stats_of(&words);
        let pixels = self.width as u64 * self.height as u64;
        Ok(TerminationOutput {
            radiance,
            motion: primary.iter().map(|p| p.motion).collect(),
            path_length,
            mean_path_length: stats.path_vertices as f64 / 256.0 / pixels as f64,
            stats,
            cache: CacheStatistics::of(&self.read_records(gpu)?),
            timings,
            rays: stats.trace_rays as u64 + stats.propagate_rays as u64,
            shaded: pixels + stats.propagated as u64 + stats.incomplete as u64,
        })
    }
}
