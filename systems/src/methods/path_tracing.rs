//! Plain path tracing at k samples per pixel: the baseline every cache is measured against.

use anyhow::Result;

use super::{FrameContext, FrameMethod, MethodOutput};

pub struct PathTracing {
    spp: u32,
}

impl PathTracing {
    pub fn new(spp: u32) -> Self {
        Self { spp }
    }
}

impl FrameMethod for PathTracing {
    fn label(&self) -> String {
        format!("pt_{}spp", self.spp)
    }

    fn spp(&self) -> u32 {
        self.spp
    }

    fn render(&mut self, ctx: &mut FrameContext) -> Result<MethodOutput> {
        let out = ctx.tracer.render(ctx.gpu, self.spp, ctx.scenario.seed, ctx.frame)?;
        Ok(MethodOutput::timed(out.radiance, out.gbuffer.motion, &out.timings, out.rays, out.shaded))
    }
}
