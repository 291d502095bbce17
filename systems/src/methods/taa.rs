//! TAA over jittered 1 spp path tracing (render::taa): the temporal baseline of issue 5.

use anyhow::Result;
use render::taa::{Taa, TaaSettings};

use super::{FrameContext, FrameMethod, MethodOutput};

pub struct TaaMethod {
    settings: TaaSettings,
    /// Built on the first frame: its passes bind the shared tracer's layouts.
    taa: Option<Taa>,
}

impl TaaMethod {
    pub fn new(settings: TaaSettings) -> Result<Self> {
        settings.validate()?;
        Ok(Self { settings, taa: None })
    }
}

impl FrameMethod for TaaMethod {
    fn label(&self) -> String {
        "taa".into()
    }

    fn spp(&self) -> u32 {
        1
    }

    fn render(&mut self, ctx: &mut FrameContext) -> Result<MethodOutput> {
        if self.taa.is_none() {
            self.taa = Some(Taa::new(ctx.gpu, ctx.tracer, self.settings)?);
        }
        let taa = self.taa.as_mut().expect("built above");
        let out = taa.render(ctx.gpu, ctx.tracer, ctx.scenario.seed, ctx.frame)?;
        let n = out.history_length.len().max(1) as f64;
        let rejected = out.history_length.iter().filter(|&&l| l <= 1.0).count() as f64 / n;
        let mean_length = out.history_length.iter().map(|&l| l as f64).sum::<f64>() / n;
        Ok(MethodOutput {
            stats: vec![("history_rejected".into(), rejected), ("history_length_mean".into(), mean_length)],
            ..MethodOutput::timed(out.radiance, out.motion, &out.timings, out.rays, out.shaded)
        })
    }
}
