//! The reliability grid on the GPU: its moments from a training step's samples (the last part of
//! the step, with the step's commit), or from explicit samples without training.

use super::train::{Groups, Stage, TrainStep};
use super::{Call, NeuralCache, bind, dispatch, groups_for};
use crate::error::NircError;
use crate::records::ReliabilitySample;
use crate::reliability::cell_count;
use render::gpu::Gpu;

impl NeuralCache {
    /// The `nirc::reliability_update` part: the per-sample moment walk (not for the batch-mean
    /// rule), the grid's update, the step's commit.
    pub(super) fn reliability_stages<'a>(&'a self, s: &'a TrainStep) -> Vec<Stage<'a>> {
        let p = &self.pipelines;
        let mut stages: Vec<Stage> = Vec::new();
        if self.config.reliability.update == crate::config::MomentUpdate::PerSample {
            stages.push((
                "reliability walk",
                &p.reliability_walk,
                &s.walk,
                Groups::Direct(groups_for(s.n as u64)),
            ));
        }
        stages.push((
            "reliability update",
            &p.reliability_update,
            &self.groups.reliability_update,
            Groups::Direct(groups_for(cell_count(&self.config.reliability) as u64)),
        ));
        stages.push(("finish step", &p.finish_step, &s.finish, Groups::Direct(1)));
        stages
    }

    /// The bind groups of the reliability accumulation and walk over `samples`.
    pub(super) fn reliability_groups(
        &self,
        gpu: &Gpu,
        call: &wgpu::Buffer,
        samples: &wgpu::Buffer,
    ) -> (wgpu::BindGroup, wgpu::BindGroup) {
        let b = &self.buffers;
        let p = &self.pipelines;
        let accumulate = bind(
            gpu,
            "nirc reliability accumulate",
            &p.reliability_accumulate,
            &[
                (0, call),
                (1, &b.hyper),
                (2, samples),
                (3, &b.reliability_accum),
                (4, &b.counters),
                (5, &b.sample_cells),
            ],
        );
        let walk = bind(
            gpu,
            "nirc reliability walk",
            &p.reliability_walk,
            &[
                (0, call),
                (1, &b.hyper),
                (2, samples),
                (3, &b.reliability_accum),
                (4, &b.moments),
                (5, &b.sample_cells),
            ],
        );
        (accumulate, walk)
    }

    /// The per-sample moment updates (nothing to do for the batch-mean rule).
    fn dispatch_walk(&self, pass: &mut wgpu::ComputePass, walk: &wgpu::BindGroup, n: u32) {
        if self.config.reliability.update == crate::config::MomentUpdate::PerSample {
            dispatch(pass, &self.pipelines.reliability_walk, walk, groups_for(n as u64));
        }
    }

    /// One update of the reliability grid from explicit samples (no training): what a training
    /// step does with its own samples. For tests and for callers that score other predictors.
    pub fn update_reliability(
        &self,
        gpu: &Gpu,
        samples: &wgpu::Buffer,
        n: u32,
    ) -> Result<(), NircError> {
        if n == 0 {
            return Ok(());
        }
        Self::check_items(
            "reliability samples",
            samples,
            n,
            std::mem::size_of::<ReliabilitySample>() as u64,
        )?;
        if n > self.config.max_batch {
            return Err(NircError::BatchTooLarge { requested: n, max: self.config.max_batch });
        }
        let b = &self.buffers;
        let p = &self.pipelines;
        let call = Self::call_buffer(gpu, Call::new(n, 1, 0));
        let (acc, walk) = self.reliability_groups(gpu, &call, samples);
        let finish = bind(
            gpu,
            "nirc finish",
            &p.finish_step,
            &[(0, &call), (1, &b.hyper), (2, &b.counters)],
        );
        gpu.submit("nirc reliability", |encoder| {
            encoder.clear_buffer(&b.reliability_accum, 0, None);
            let mut pass = encoder.begin_compute_pass(&wgpu::ComputePassDescriptor {
                label: Some("nirc reliability"),
                timestamp_writes: None,
            });
            dispatch(&mut pass, &p.reliability_accumulate, &acc, groups_for(n as u64));
            self.dispatch_walk(&mut pass, &walk, n);
            dispatch(
                &mut pass,
                &p.reliability_update,
                &self.groups.reliability_update,
                groups_for(cell_count(&self.config.reliability) as u64),
            );
            dispatch(&mut pass, &p.finish_step, &finish, 1);
            Ok(())
        })
    }
}
