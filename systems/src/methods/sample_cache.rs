//! The stable sample cache as a frame method (render::sample_cache): its GPU state is created on
//! the first frame from the shared path tracer, then carried from frame to frame.

use anyhow::Result;
use render::sample_cache::{SampleCache, SampleCacheSettings};

use super::{FrameContext, FrameMethod, MethodImage, MethodOutput};

pub struct SampleCacheMethod {
    settings: SampleCacheSettings,
    cache: Option<SampleCache>,
}

impl SampleCacheMethod {
    pub fn new(settings: SampleCacheSettings) -> Self {
        Self { settings, cache: None }
    }
}

impl FrameMethod for SampleCacheMethod {
    fn label(&self) -> String {
        self.settings.label()
    }

    fn spp(&self) -> u32 {
        (self.settings.shading_rate.ceil() as u32).max(1)
    }

    fn render(&mut self, ctx: &mut FrameContext) -> Result<MethodOutput> {
        if self.cache.is_none() {
            self.cache = Some(SampleCache::new(ctx.gpu, ctx.tracer, self.settings)?);
        }
        let cache = self.cache.as_mut().expect("created above");
        let out = cache.render(ctx.gpu, ctx.tracer, ctx.scenario.seed, ctx.frame)?;
        let s = &out.stats;
        let pixels = out.radiance.len().max(1) as f64;
        let n = self.settings.slots as f64;
        let stats = vec![
            ("primary_rays".to_string(), s.rays as f64),
            ("new_samples".to_string(), s.new_samples as f64),
            ("purged_samples".to_string(), s.purged as f64),
            ("reprojected_samples".to_string(), s.reprojected as f64),
            ("dropped_samples".to_string(), s.dropped as f64),
            ("visible_per_pixel".to_string(), s.visible as f64 / pixels),
            ("occupancy".to_string(), s.occupied as f64 / (pixels * n)),
            ("slope_flagged_pixels".to_string(), s.slope_flagged as f64),
        ];
        // Trace mask (red: slope test, green: base rate, blue: hole), as the paper's figure 4.
        let trace_mask = out
            .flags
            .iter()
            .map(|f| {
                let on = |bit: u32| if f & bit != 0 { 1.0 } else { 0.0 };
                [on(render::sample_cache::FLAG_SLOPE), on(render::sample_cache::FLAG_BASE), on(render::sample_cache::FLAG_HOLE), 1.0]
            })
            .collect();
        Ok(MethodOutput {
            stats,
            images: vec![MethodImage { name: "trace_mask".into(), pixels: trace_mask, hdr: false }],
            ..MethodOutput::timed(out.radiance, out.motion, &out.timings, s.all_rays as u64, s.shaded as u64)
        })
    }
}
