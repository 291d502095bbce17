//! One submission of passes: their pipelines and workgroups.

use super::TerminationCache;
use super::passes::{INSERT_ROUNDS, TcPass};
use crate::settings::VERTICES_PER_RECORD;
use render::error::RenderError;
use render::gpu::Gpu;
use render::scene_gpu::SceneGpu;
use render::timing::{PassTimer, PassTiming};

impl TerminationCache {
    /// `passes` in order as one submission timed by `timer` (whose names are theirs), bound
    /// with `group` (the own tracer's, or another tracer's for its trace).
    pub(super) fn submit(
        &self,
        gpu: &Gpu,
        scene: &SceneGpu,
        timer: &PassTimer,
        passes: &[TcPass],
        group: &wgpu::BindGroup,
    ) -> Result<Vec<PassTiming>, RenderError> {
        let mut timed = timer.begin(gpu, "termination");
        for (index, &p) in passes.iter().enumerate() {
            debug_assert_eq!(timer.names()[index], p.name());
            if p == TcPass::Insert {
                timed.encoder().copy_buffer_to_buffer(&self.inserts, 0, &self.insert_args, 0, 12);
                timed.pass(index, |pass| {
                    self.frame.bind(gpu, scene, pass);
                    pass.set_bind_group(2, group, &[]);
                    let [claim, win, settle] = [4, 5, 6].map(|e| self.pipelines[e].get());
                    for _ in 0..INSERT_ROUNDS.min(self.settings.probe_limit) {
                        pass.set_pipeline(&claim);
                        pass.dispatch_workgroups_indirect(&self.insert_args, 0);
                        pass.set_pipeline(&win);
                        pass.dispatch_workgroups_indirect(&self.insert_args, 0);
                    }
                    pass.set_pipeline(&settle);
                    pass.dispatch_workgroups_indirect(&self.insert_args, 0);
                })?;
                continue;
            }
            let entry = match p {
                TcPass::Propagate => 0,
                TcPass::Fold => 1,
                TcPass::Trace => 2,
                TcPass::Insert | TcPass::Store => 3,
            };
            let pipeline = &self.pipelines[entry];
            let [x, y, z] = self.workgroups(p);
            timed.pass(index, |pass| {
                pass.set_pipeline(&pipeline.get());
                self.frame.bind(gpu, scene, pass);
                pass.set_bind_group(2, group, &[]);
                pass.dispatch_workgroups(x, y, z);
            })?;
        }
        timed.submit()
    }

    /// Workgroups of `pass`: per stored vertex, per record, or per 8x8 pixels.
    pub(super) fn workgroups(&self, pass: TcPass) -> [u32; 3] {
        let records = self.settings.capacity;
        match pass {
            TcPass::Propagate => [(records * VERTICES_PER_RECORD as u32).div_ceil(64), 1, 1],
            TcPass::Fold | TcPass::Store => [records.div_ceil(64), 1, 1],
            // Dispatched indirectly over the frame's requests (`inserts`).
            TcPass::Insert => [0, 1, 1],
            TcPass::Trace => [self.width.div_ceil(8), self.height.div_ceil(8), 1],
        }
    }
}
