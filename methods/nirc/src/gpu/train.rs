//! A training step on the GPU: its bind groups, its dispatches in order (Adam, the EMA, the
//! reliability grid), submitted at once, as timed passes of a frame, or one by one for a profile.

use super::shaders::{self, CHUNK};
use super::{
    Call, NeuralCache, WORKGROUP_SIZE, bind, bind_with_views, dispatch, grid_textures, groups_for,
    readback,
};
use crate::error::NircError;
use crate::records::TrainingRecord;
use render::gpu::Gpu;
use render::timing::TimedFrame;

/// The three parts of a training step, in the order they run: each a pass of its own in a frame
/// (the `nirc::train`, `nirc::ema` and `nirc::reliability_update` systems).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum StepPart {
    /// Forward and backward passes, gradients and the Adam step of the High-LR weights (with
    /// the step's reliability samples accumulated).
    Adam,
    /// The debiased EMA of the weights after the Adam step.
    Ema,
    /// The reliability grid's moments from the step's samples, then the step's commit (or
    /// roll-back count).
    Reliability,
}

impl StepPart {
    pub const ALL: [StepPart; 3] = [StepPart::Adam, StepPart::Ema, StepPart::Reliability];
}

/// The bind groups of one training step ([`NeuralCache::prepare_step`]).
pub struct TrainStep {
    pub(super) n: u32,
    num_chunks: u32,
    fb: wgpu::BindGroup,
    accumulate: wgpu::BindGroup,
    pub(super) walk: wgpu::BindGroup,
    partial: Option<wgpu::BindGroup>,
    reduce: wgpu::BindGroup,
    check: wgpu::BindGroup,
    apply: wgpu::BindGroup,
    ema: wgpu::BindGroup,
    pub(super) finish: wgpu::BindGroup,
    /// With sparse grid updates, the groups of adam_sparse.wgsl's passes (as `Pipelines::sparse`).
    sparse: Option<[wgpu::BindGroup; 7]>,
}

/// How many workgroups a dispatch runs: a count, or what the GPU wrote into a buffer.
#[derive(Clone, Copy)]
pub(super) enum Groups<'a> {
    Direct(u32),
    Indirect(&'a wgpu::Buffer),
}

/// One dispatch of a training step: name (for the profile), pipeline, bind group, workgroups.
pub(super) type Stage<'a> =
    (&'static str, &'a wgpu::ComputePipeline, &'a wgpu::BindGroup, Groups<'a>);

/// Parameter quads each invocation of Adam's and the EMA's passes updates (their loops stride
/// over the whole vector): the per-invocation work (the step's bias corrections and the flag,
/// read from `counters`) is then paid once per 4 quads. On lavapipe one quad per invocation
/// made these passes 1.3-1.6x slower (docs/lab/nirc-speed.md); 16 was slower again.
const PARAM_QUADS_PER_INVOCATION: u64 = 4;

impl NeuralCache {
    /// One training step on the first `n` records of `records` (array of `TrainingRecord`),
    /// submitted at once. A step with a non-finite loss, gradient or weight is rolled back on
    /// the GPU and counted in `Counters::rejected_steps`.
    pub fn train(&self, gpu: &Gpu, records: &wgpu::Buffer, n: u32) -> Result<(), NircError> {
        gpu.submit("nirc train", |encoder| self.encode_train(gpu, encoder, records, n))
    }

    /// Records one training step into the caller's encoder (e.g. after the path tracer's pass
    /// that wrote `records`): Adam, the EMA of the weights, the reliability grid, the step's
    /// commit. Steps recorded in order run in order.
    pub fn encode_train(
        &self,
        gpu: &Gpu,
        encoder: &mut wgpu::CommandEncoder,
        records: &wgpu::Buffer,
        n: u32,
    ) -> Result<(), NircError> {
        let Some(step) = self.prepare_step(gpu, records, n)? else { return Ok(()) };
        self.clear_step(encoder);
        let mut pass = encoder.begin_compute_pass(&wgpu::ComputePassDescriptor {
            label: Some("nirc train"),
            timestamp_writes: None,
        });
        for part in StepPart::ALL {
            Self::dispatch_stages(&mut pass, &self.stages(part, &step));
        }
        Ok(())
    }

    /// The bind groups and sizes of one training step on the first `n` of `records`; `None` for
    /// no records. Then [`Self::part_timed`] for each of [`StepPart::ALL`] in this order, each its
    /// own pass.
    pub fn prepare_step(
        &self,
        gpu: &Gpu,
        records: &wgpu::Buffer,
        n: u32,
    ) -> Result<Option<TrainStep>, NircError> {
        if n == 0 {
            return Ok(None);
        }
        if n > self.config.max_batch {
            return Err(NircError::BatchTooLarge { requested: n, max: self.config.max_batch });
        }
        Self::check_items(
            "training records",
            records,
            n,
            std::mem::size_of::<TrainingRecord>() as u64,
        )?;
        let b = &self.buffers;
        let p = &self.pipelines;
        let num_chunks = n.div_ceil(CHUNK);
        let call = Self::call_buffer(gpu, Call::new(n, 0, num_chunks));
        let mut fb_entries: Vec<(u32, &wgpu::Buffer)> = vec![
            (0, &call),
            (1, &b.hyper),
            (2, records),
            (3, &b.params),
            (4, &b.ema),
            (5, &b.scratch),
            (6, &b.grid_accum),
            (7, &b.samples),
            (8, &b.losses),
            (9, &b.counters),
        ];
        if self.placement.tiled_training() {
            fb_entries.push((10, &b.partials));
        }
        if let Some(sb) = &b.sparse {
            fb_entries.push((shaders::SPARSE_MARK_BINDING, &sb.touched_bits));
        }
        let fb = bind_with_views(
            gpu,
            "nirc train",
            &p.train,
            &fb_entries,
            &self.grid_views(grid_textures::READ_BINDINGS),
        );
        let (accumulate, walk) = self.reliability_groups(gpu, &call, &b.samples);
        let partial = p.weight_partial.as_ref().map(|wp| {
            bind(gpu, "nirc weight partial", wp, &[(0, &call), (1, &b.scratch), (2, &b.partials)])
        });
        let reduce = bind(
            gpu,
            "nirc weight reduce",
            &p.weight_reduce,
            &[(0, &call), (2, &b.partials), (3, &b.grad)],
        );
        let adam_entries: &[(u32, &wgpu::Buffer)] = &[
            (0, &call),
            (1, &b.hyper),
            (2, &b.params),
            (3, &b.ema),
            (4, &b.adam_m),
            (5, &b.adam_v),
            (6, &b.grad),
            (7, &b.grid_accum),
            (8, &b.counters),
        ];
        let check = bind(gpu, "nirc adam check", &p.adam_check, adam_entries);
        // `apply` does not read the EMA (adam_ema.wgsl), so its layout has no binding 3.
        let apply_entries: Vec<(u32, &wgpu::Buffer)> =
            adam_entries.iter().copied().filter(|&(binding, _)| binding != 3).collect();
        // The grid mirror's write views, if any: apply writes the High-LR one, the EMA pass the other.
        let mirror = self.grid_views(grid_textures::WRITE_BINDINGS);
        let (params_out, ema_out) = mirror.split_at(mirror.len() / 2);
        let apply =
            bind_with_views(gpu, "nirc adam apply", &p.adam_apply, &apply_entries, params_out);
        let ema = bind_with_views(
            gpu,
            "nirc ema update",
            &p.ema_update,
            &[(1, &b.hyper), (2, &b.params), (3, &b.ema), (8, &b.counters)],
            ema_out,
        );
        let finish = bind(
            gpu,
            "nirc finish",
            &p.finish_step,
            &[(0, &call), (1, &b.hyper), (2, &b.counters)],
        );
        let sparse = self.sparse_groups(gpu, &call);
        Ok(Some(TrainStep {
            sparse,
            n,
            num_chunks,
            fb,
            accumulate,
            walk,
            partial,
            reduce,
            check,
            apply,
            ema,
            finish,
        }))
    }

    /// The bind groups of adam_sparse.wgsl's and touched_list.wgsl's passes for a step with
    /// `call`, in the order of `Pipelines::sparse`; none without sparse grid updates.
    fn sparse_groups(&self, gpu: &Gpu, call: &wgpu::Buffer) -> Option<[wgpu::BindGroup; 7]> {
        let b = &self.buffers;
        let (pipelines, sb) = (self.pipelines.sparse.as_ref()?, b.sparse.as_ref()?);
        let mirror = self.grid_views(grid_textures::WRITE_BINDINGS);
        let (params_out, ema_out) = mirror.split_at(mirror.len() / 2);
        let [clear, check, apply, ema, count, scan, emit] = pipelines;
        // What every pass over the touched list binds; Adam's add its moments, the EMA its average.
        let over_list = |label: &str,
                         pipeline: &wgpu::ComputePipeline,
                         extra: &[(u32, &wgpu::Buffer)],
                         views: &[(u32, &wgpu::TextureView)]| {
            let mut entries: Vec<(u32, &wgpu::Buffer)> = vec![
                (0, call),
                (1, &b.hyper),
                (2, &b.params),
                (7, &b.grid_accum),
                (8, &b.counters),
                (11, &sb.grid_steps),
                (12, &sb.bias_powers),
                (13, &sb.touched),
                (14, &sb.touched_len),
            ];
            entries.extend(extra);
            bind_with_views(gpu, label, pipeline, &entries, views)
        };
        let moments: [(u32, &wgpu::Buffer); 2] = [(4, &b.adam_m), (5, &b.adam_v)];
        Some([
            bind(
                gpu,
                "nirc clear touched",
                clear,
                &[(13, &sb.touched), (14, &sb.touched_len), (16, &b.grid_accum)],
            ),
            over_list("nirc adam check grid", check, &[moments[0], moments[1], (3, &b.ema)], &[]),
            over_list("nirc adam apply grid", apply, &moments, params_out),
            over_list("nirc ema grid", ema, &[(3, &b.ema)], ema_out),
            bind(
                gpu,
                "nirc count touched",
                count,
                &[(15, &sb.touched_bits), (18, &sb.block_counts)],
            ),
            bind(
                gpu,
                "nirc scan touched",
                scan,
                &[
                    (14, &sb.touched_len),
                    (15, &sb.touched_bits),
                    (17, &sb.list_dispatch),
                    (18, &sb.block_counts),
                    (19, &sb.block_offsets),
                ],
            ),
            bind(
                gpu,
                "nirc list touched",
                emit,
                &[(13, &sb.touched), (15, &sb.touched_bits), (19, &sb.block_offsets)],
            ),
        ])
    }

    /// One part of a training step as pass `index` of a timed frame (the Adam part first zeroes
    /// the step's accumulators).
    pub fn part_timed(
        &self,
        timed: &mut TimedFrame,
        index: usize,
        step: &TrainStep,
        part: StepPart,
    ) -> Result<(), NircError> {
        if part == StepPart::Adam {
            self.clear_step(timed.encoder());
        }
        timed.pass(index, |pass| Self::dispatch_stages(pass, &self.stages(part, step)))?;
        Ok(())
    }

    /// The dispatches of one part of a step, in order.
    fn stages<'a>(&'a self, part: StepPart, s: &'a TrainStep) -> Vec<Stage<'a>> {
        match part {
            StepPart::Adam => self.adam_stages(s),
            StepPart::Ema => self.ema_stages(s),
            StepPart::Reliability => self.reliability_stages(s),
        }
    }

    /// Zeroes the step's accumulators: every grid gradient sum, or with sparse grid updates the
    /// touched bitmask only (`clear_touched` zeroes the last step's listed sums, a stage of the
    /// step).
    fn clear_step(&self, encoder: &mut wgpu::CommandEncoder) {
        match &self.buffers.sparse {
            Some(sb) => encoder.clear_buffer(&sb.touched_bits, 0, None),
            None => encoder.clear_buffer(&self.buffers.grid_accum, 0, None),
        }
        encoder.clear_buffer(&self.buffers.reliability_accum, 0, None);
    }

    /// The dispatches of a step's `nirc::train` part in order: forward and backward passes,
    /// gradients, the Adam step (name, pipeline, bind group, workgroups).
    fn adam_stages<'a>(&'a self, s: &'a TrainStep) -> Vec<Stage<'a>> {
        let p = &self.pipelines;
        let all = Groups::Direct(self.param_groups());
        let sparse = p.sparse.as_ref().zip(s.sparse.as_ref()).zip(self.buffers.sparse.as_ref());
        let mut stages: Vec<Stage> = Vec::new();
        if let Some(((pipelines, groups), sb)) = sparse {
            let list = Groups::Indirect(&sb.list_dispatch);
            stages.push((
                "clear the last step's touched grid quads",
                &pipelines[0],
                &groups[0],
                list,
            ));
        }
        stages.extend([
            (
                "train (forward, backward)",
                &p.train,
                &s.fb,
                Groups::Direct(s.n.div_ceil(WORKGROUP_SIZE)),
            ),
            (
                "reliability accumulate",
                &p.reliability_accumulate,
                &s.accumulate,
                Groups::Direct(groups_for(s.n as u64)),
            ),
        ]);
        if let (Some(pipeline), Some(group)) = (&p.weight_partial, &s.partial) {
            stages.push((
                "weight gradient partials",
                pipeline,
                group,
                Groups::Direct(groups_for(self.layout.mlp_params as u64 * s.num_chunks as u64)),
            ));
        }
        stages.push((
            "weight gradient reduce",
            &p.weight_reduce,
            &s.reduce,
            Groups::Direct(groups_for(self.layout.mlp_params as u64)),
        ));
        if let Some(((pipelines, groups), sb)) = sparse {
            let list = Groups::Indirect(&sb.list_dispatch);
            let blocks = Groups::Direct(sb.blocks);
            stages.extend([
                ("count the touched grid quads", &pipelines[4], &groups[4], blocks),
                ("scan the counts", &pipelines[5], &groups[5], Groups::Direct(1)),
                ("list the touched grid quads", &pipelines[6], &groups[6], blocks),
                ("adam check (MLP)", &p.adam_check, &s.check, all),
                ("adam check (touched grid quads)", &pipelines[1], &groups[1], list),
                ("adam apply (MLP)", &p.adam_apply, &s.apply, all),
                ("adam apply (touched grid quads)", &pipelines[2], &groups[2], list),
            ]);
        } else {
            stages.push(("adam check (every parameter)", &p.adam_check, &s.check, all));
            stages.push(("adam apply (every parameter)", &p.adam_apply, &s.apply, all));
        }
        stages
    }

    /// Workgroups of the dense passes over parameter quads (Adam's check and apply, the EMA):
    /// every quad, or with sparse grid updates the MLP's.
    fn param_groups(&self) -> u32 {
        let params = if self.buffers.sparse.is_some() {
            self.layout.mlp_params
        } else {
            self.layout.total_params
        };
        groups_for((params as u64 / 4).div_ceil(PARAM_QUADS_PER_INVOCATION))
    }

    /// The `nirc::ema` part: the debiased EMA of every parameter (with sparse grid updates, of
    /// the MLP and of the touched grid quads).
    fn ema_stages<'a>(&'a self, s: &'a TrainStep) -> Vec<Stage<'a>> {
        let p = &self.pipelines;
        let all = Groups::Direct(self.param_groups());
        match (&p.sparse, &s.sparse, &self.buffers.sparse) {
            (Some(pipelines), Some(groups), Some(sb)) => vec![
                ("ema update (MLP)", &p.ema_update, &s.ema, all),
                (
                    "ema update (touched grid quads)",
                    &pipelines[3],
                    &groups[3],
                    Groups::Indirect(&sb.list_dispatch),
                ),
            ],
            _ => vec![("ema update (every parameter)", &p.ema_update, &s.ema, all)],
        }
    }

    fn dispatch_stages(pass: &mut wgpu::ComputePass, stages: &[Stage]) {
        for &(_, pipeline, group, workgroups) in stages {
            match workgroups {
                Groups::Direct(n) => dispatch(pass, pipeline, group, n),
                Groups::Indirect(args) => {
                    pass.set_pipeline(pipeline);
                    pass.set_bind_group(0, group, &[]);
                    pass.dispatch_workgroups_indirect(args, 0);
                }
            }
        }
    }

    /// Seconds per dispatch of one training step on `n` of `records`, each stage submitted and
    /// waited for alone, `reps` times after a warm-up: the profile `flicker bench --nirc` prints.
    pub fn train_stage_seconds(
        &self,
        gpu: &Gpu,
        records: &wgpu::Buffer,
        n: u32,
        reps: u32,
    ) -> Result<Vec<(&'static str, f64)>, NircError> {
        let Some(s) = self.prepare_step(gpu, records, n)? else { return Ok(Vec::new()) };
        let timed = |name: &'static str,
                     record: &dyn Fn(&mut wgpu::CommandEncoder)|
         -> Result<f64, NircError> {
            let run = || {
                gpu.submit(name, |encoder| {
                    record(encoder);
                    Ok::<_, NircError>(())
                })?;
                readback::wait_idle(gpu)
            };
            run()?;
            let t = std::time::Instant::now();
            for _ in 0..reps {
                run()?;
            }
            Ok(t.elapsed().as_secs_f64() / reps.max(1) as f64)
        };
        let mut out = Vec::new();
        for stage in StepPart::ALL.into_iter().flat_map(|part| self.stages(part, &s)) {
            let seconds = timed(stage.0, &|encoder| {
                let mut pass = encoder.begin_compute_pass(&wgpu::ComputePassDescriptor {
                    label: Some(stage.0),
                    timestamp_writes: None,
                });
                Self::dispatch_stages(&mut pass, &[stage]);
            })?;
            out.push((stage.0, seconds));
        }
        out.push((
            "clear the step's accumulators",
            timed("clear", &|encoder| self.clear_step(encoder))?,
        ));
        Ok(out)
    }
}
