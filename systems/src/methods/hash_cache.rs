//! World-space hash cache (render::hash_cache), optionally under TAA as the paper runs it.

use anyhow::Result;
use render::hash_cache::{HashCache, HashCacheSettings};
use render::taa::{Taa, TaaSettings};

use super::{FrameContext, FrameMethod, MethodOutput};

pub struct HashCacheMethod {
    settings: HashCacheSettings,
    taa: Option<TaaSettings>,
    label: String,
    /// Built on the first frame: the passes bind the shared tracer's layouts.
    state: Option<(HashCache, Option<Taa>)>,
}

impl HashCacheMethod {
    pub fn new(settings: HashCacheSettings, taa: Option<TaaSettings>, label: String) -> Result<Self> {
        settings.validate()?;
        if let Some(t) = &taa {
            t.validate()?;
        }
        Ok(Self { settings, taa, label, state: None })
    }
}

impl FrameMethod for HashCacheMethod {
    fn label(&self) -> String {
        self.label.clone()
    }

    fn spp(&self) -> u32 {
        1
    }

    fn render(&mut self, ctx: &mut FrameContext) -> Result<MethodOutput> {
        if self.state.is_none() {
            let cache = HashCache::new(ctx.gpu, ctx.tracer, self.settings)?;
            let taa = self.taa.map(|s| Taa::new(ctx.gpu, ctx.tracer, s)).transpose()?;
            self.state = Some((cache, taa));
        }
        let (cache, taa) = self.state.as_mut().expect("built above");
        let out = cache.render(ctx.gpu, ctx.tracer, &ctx.scene.camera, ctx.scenario.seed, ctx.frame, taa.as_mut())?;
        let s = out.stats;
        Ok(MethodOutput {
            stats: vec![
                ("cache_occupancy".into(), s.occupancy()),
                ("cache_used_cells".into(), s.occupied as f64),
                ("cache_evictions".into(), s.evicted as f64),
                ("cache_insertions".into(), s.inserted as f64),
                ("cache_insert_failures".into(), s.insert_failures as f64),
                ("cache_update_paths".into(), s.update_paths as f64),
            ],
            ..MethodOutput::timed(out.radiance, out.motion, &out.timings, out.rays, out.shaded)
        })
    }
}
