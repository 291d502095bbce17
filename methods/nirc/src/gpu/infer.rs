//! Inference on the GPU: the blend of both predictors at a buffer of queries, or the diagnostic
//! look-up of the reliability grid, recorded into an encoder, submitted, or as a timed pass.

use super::shaders::{self, WeightPlacement};
use super::{Call, NeuralCache, WORKGROUP_SIZE, bind_with_views, dispatch, grid_textures, lane};
use crate::config::PredictorMode;
use crate::error::NircError;
use crate::records::{CacheAnswer, CacheQuery};
use render::gpu::Gpu;
use render::timing::TimedFrame;

/// `Call::mode` of the diagnostic reliability look-up (after the four `PredictorMode` codes).
const RELIABILITY_MODE: u32 = 4;

impl NeuralCache {
    /// Answers the first `n` queries of `queries` (array of `CacheQuery`) into `out` (array of
    /// `CacheAnswer`): radiance max(0, (1 - σ) f_EMA + σ f_cur) and σ. Submitted at once.
    pub fn infer(
        &self,
        gpu: &Gpu,
        queries: &wgpu::Buffer,
        n: u32,
        out: &wgpu::Buffer,
        mode: PredictorMode,
    ) -> Result<(), NircError> {
        gpu.submit("nirc infer", |encoder| self.encode_infer(gpu, encoder, queries, n, out, mode))
    }

    /// [`Self::encode_infer`] as pass `index` of a timed frame.
    pub fn infer_timed(
        &self,
        gpu: &Gpu,
        timed: &mut TimedFrame,
        index: usize,
        queries: &wgpu::Buffer,
        n: u32,
        out: &wgpu::Buffer,
        mode: PredictorMode,
    ) -> Result<(), NircError> {
        let Some(group) =
            self.infer_group(gpu, queries, n, out, (mode.code(), mode.fixed_sigma()))?
        else {
            return Ok(());
        };
        timed.pass(index, |pass| self.dispatch_infer(pass, &group, n))?;
        Ok(())
    }

    /// Records the inference of `n` queries into the caller's encoder.
    pub fn encode_infer(
        &self,
        gpu: &Gpu,
        encoder: &mut wgpu::CommandEncoder,
        queries: &wgpu::Buffer,
        n: u32,
        out: &wgpu::Buffer,
        mode: PredictorMode,
    ) -> Result<(), NircError> {
        self.encode_infer_code(gpu, encoder, queries, n, out, (mode.code(), mode.fixed_sigma()))
    }

    /// Records a diagnostic look-up of the reliability grid at `n` queries (no network): each
    /// answer is (r̄_cur, r̄_EMA, σ of the blend, 1 once the grid is past its warm-up else 0),
    /// the signal behind preference maps and the mean reliability per frame.
    pub fn encode_reliability(
        &self,
        gpu: &Gpu,
        encoder: &mut wgpu::CommandEncoder,
        queries: &wgpu::Buffer,
        n: u32,
        out: &wgpu::Buffer,
    ) -> Result<(), NircError> {
        self.encode_infer_code(gpu, encoder, queries, n, out, (RELIABILITY_MODE, 0.0))
    }

    fn encode_infer_code(
        &self,
        gpu: &Gpu,
        encoder: &mut wgpu::CommandEncoder,
        queries: &wgpu::Buffer,
        n: u32,
        out: &wgpu::Buffer,
        mode: (u32, f32),
    ) -> Result<(), NircError> {
        let Some(group) = self.infer_group(gpu, queries, n, out, mode)? else { return Ok(()) };
        let mut pass = encoder.begin_compute_pass(&wgpu::ComputePassDescriptor {
            label: Some("nirc infer"),
            timestamp_writes: None,
        });
        self.dispatch_infer(&mut pass, &group, n);
        Ok(())
    }

    /// Every inference goes through here: the register form first stages the weights as this
    /// inference must see them (the last committed step's), then the inference pass.
    fn dispatch_infer(&self, pass: &mut wgpu::ComputePass, group: &wgpu::BindGroup, n: u32) {
        if let (Some(stage), Some(stage_group)) =
            (&self.pipelines.lane_stage, &self.groups.lane_stage)
        {
            dispatch(
                pass,
                stage,
                stage_group,
                (lane::uniform_bytes(&self.layout) / 16).div_ceil(WORKGROUP_SIZE),
            );
        }
        dispatch(pass, &self.pipelines.infer, group, self.infer_groups(n));
    }

    /// Workgroups of an inference of `n` queries.
    fn infer_groups(&self, n: u32) -> u32 {
        match self.placement {
            WeightPlacement::Tiled => n.div_ceil(shaders::INFER_TILE_QUERIES),
            WeightPlacement::Storage => n.div_ceil(WORKGROUP_SIZE),
            // LANE_QUERIES queries per invocation (infer_lane.wgsl).
            WeightPlacement::Registers => n.div_ceil(lane::LANE_QUERIES * WORKGROUP_SIZE),
        }
    }

    /// The bind group of an inference of `n` queries; `None` for no queries.
    fn infer_group(
        &self,
        gpu: &Gpu,
        queries: &wgpu::Buffer,
        n: u32,
        out: &wgpu::Buffer,
        mode: (u32, f32),
    ) -> Result<Option<wgpu::BindGroup>, NircError> {
        if n == 0 {
            return Ok(None);
        }
        Self::check_items("cache queries", queries, n, std::mem::size_of::<CacheQuery>() as u64)?;
        Self::check_items("cache answers", out, n, std::mem::size_of::<CacheAnswer>() as u64)?;
        let groups = self.infer_groups(n);
        if groups > gpu.limits.max_compute_workgroups_per_dimension {
            return Err(NircError::Config(format!(
                "{n} queries need {groups} workgroups, over this adapter's limit"
            )));
        }
        let b = &self.buffers;
        let call = Self::call_buffer(gpu, Call { fixed_sigma: mode.1, ..Call::new(n, mode.0, 0) });
        let mut entries = vec![
            (0, &call),
            (1, &b.hyper),
            (2, queries),
            (3, &b.params),
            (4, &b.ema),
            (5, &b.moments),
            (6, &b.counters),
            (7, out),
        ];
        if let Some(staged) = &b.lane_staged {
            entries.push((8, staged));
        }
        if b.grid.is_some() {
            // The register form then reads the grid from the mirror and its weights from the
            // staged uniform: the parameter buffers are not in its layout.
            entries.retain(|&(binding, _)| binding != 3 && binding != 4);
        }
        Ok(Some(bind_with_views(
            gpu,
            "nirc infer",
            &self.pipelines.infer,
            &entries,
            &self.grid_views(grid_textures::READ_BINDINGS),
        )))
    }
}
