//! The cache on the GPU: buffers of the whole state, the WGSL passes, and the calls a path
//! tracer makes (`train` on a buffer of training records, `infer` on a buffer of queries).
//!
//! A training step is one submission of these passes (methods/nirc/shaders/):
//!
//! ```text
//! 1. train_forward_backward  per record: both forwards, loss, backward; hash-grid gradients as
//!                            exact fixed-point sums; reliability samples (y, f_cur, f_ema)
//! 2. reliability_accumulate  per sample: its reliability cell, the cell's count and list of
//!                            samples (per sample) or fixed-point sums (per batch)
//! 3. weight_gradient         per weight and chunk of records, then over chunks (no atomics)
//! 4. adam_ema check, apply   Adam; any non-finite value raises a flag and nothing is written
//!    adam_ema ema_update     debiased EMA of the new weights (skipped on a flagged step)
//!    (adam_sparse            with sparse grid updates, the grid's part of both over the quads
//!                            the step touched only, listed in ascending order by touched_list
//!                            after pass 3; the last step's sums cleared before pass 1)
//! 5. reliability_walk        per cell (its list's head): the per-sample EMAs of the moments in
//!                            record order
//!    reliability_update      per cell: keep the new moments (or the batch-mean step)
//! 6. finish_step             commit the counters, or count the rolled-back step
//! ```
//!
//! Every sum has a fixed order or is exact, so a step is deterministic.

pub mod grid_textures;
mod infer;
pub mod lane;
pub mod readback;
mod reliability_grid;
pub(crate) mod setup;
pub mod shaders;
pub mod train;

use crate::bounds::SceneBounds;
use crate::config::{NircCacheSettings, PredictorMode};
use crate::cpu::optimizer::Counters;
use crate::error::NircError;
use crate::layout::ParameterLayout;
use crate::records::{CacheAnswer, CacheQuery, TrainingRecord};
use crate::reliability::{MOMENTS_PER_CELL, cell_count};
use crate::state::CacheState;
use bytemuck::Pod;
use render::gpu::Gpu;
use render::readback::read_pod;
use shaders::WeightPlacement;
use std::path::Path;

render::gpu_struct! {
    /// Settings that do not change during a cache's life (parameters of every pass).
    pub struct Hyper {
        pub bounds_min: [f32; 4] => "vec4<f32>",
        pub inv_extent: [f32; 4] => "vec4<f32>",
        pub learning_rate: f32 => "f32",
        pub beta1: f32 => "f32",
        pub beta2: f32 => "f32",
        pub adam_epsilon: f32 => "f32",
        pub alpha: f32 => "f32",
        pub loss_epsilon: f32 => "f32",
        pub lambda: f32 => "f32",
        pub reliability_epsilon: f32 => "f32",
        pub kappa: f32 => "f32",
        pub warmup: u32 => "u32",
        pub reliability_resolution: u32 => "u32",
        pub loss_luminance: u32 => "u32",
        /// 1: the moments move once per sample (the paper), 0: once per step (batch mean).
        pub moments_per_sample: u32 => "u32",
        pub pad0: u32 => "u32",
        pub pad1: u32 => "u32",
        pub pad2: u32 => "u32",
    }
}

render::gpu_struct! {
    /// What one train/infer call works on (its own small parameter buffer).
    pub struct Call {
        pub n: u32 => "u32",
        pub inv_n: f32 => "f32",
        pub mode: u32 => "u32",
        pub num_chunks: u32 => "u32",
        /// σ of the fixed blend (mode 5).
        pub fixed_sigma: f32 => "f32",
        pub pad0: u32 => "u32",
        pub pad1: u32 => "u32",
        pub pad2: u32 => "u32",
    }
}

impl Call {
    fn new(n: u32, mode: u32, num_chunks: u32) -> Self {
        Self {
            n,
            inv_n: 1.0 / n as f32,
            mode,
            num_chunks,
            fixed_sigma: 0.0,
            pad0: 0,
            pad1: 0,
            pad2: 0,
        }
    }
}

struct Pipelines {
    /// train_tile (tiled: forward, backward and the tile's weight-gradient sums) or
    /// train_forward_backward (per record, then `weight_partial`).
    train: wgpu::ComputePipeline,
    weight_partial: Option<wgpu::ComputePipeline>,
    weight_reduce: wgpu::ComputePipeline,
    adam_check: wgpu::ComputePipeline,
    adam_apply: wgpu::ComputePipeline,
    ema_update: wgpu::ComputePipeline,
    reliability_accumulate: wgpu::ComputePipeline,
    reliability_update: wgpu::ComputePipeline,
    reliability_walk: wgpu::ComputePipeline,
    finish_step: wgpu::ComputePipeline,
    infer: wgpu::ComputePipeline,
    /// The register form's staging of both predictors' MLP weights (lane_stage.wgsl).
    lane_stage: Option<wgpu::ComputePipeline>,
    /// With sparse grid updates: clear_touched, check_grid, apply_grid, ema_grid
    /// (adam_sparse.wgsl), count_blocks, scan_blocks, emit_list (touched_list.wgsl).
    sparse: Option<[wgpu::ComputePipeline; 7]>,
}

/// The buffers of sparse grid updates (adam_sparse.wgsl).
struct SparseBuffers {
    /// Per grid parameter, its committed Adam steps (`CacheState::grid_steps`).
    grid_steps: wgpu::Buffer,
    /// `cpu::optimizer::BiasPowers`.
    bias_powers: wgpu::Buffer,
    /// The grid quads the step touched, ascending; their bits; the list's length.
    touched: wgpu::Buffer,
    touched_bits: wgpu::Buffer,
    touched_len: wgpu::Buffer,
    /// Per block of the bitmask, its count and its first slot (touched_list.wgsl).
    block_counts: wgpu::Buffer,
    block_offsets: wgpu::Buffer,
    /// Blocks of the bitmask (workgroups of count_blocks and emit_list).
    blocks: u32,
    /// The indirect dispatch of the passes over the list.
    list_dispatch: wgpu::Buffer,
}

struct Buffers {
    hyper: wgpu::Buffer,
    params: wgpu::Buffer,
    ema: wgpu::Buffer,
    adam_m: wgpu::Buffer,
    adam_v: wgpu::Buffer,
    grad: wgpu::Buffer,
    partials: wgpu::Buffer,
    scratch: wgpu::Buffer,
    grid_accum: wgpu::Buffer,
    samples: wgpu::Buffer,
    sample_cells: wgpu::Buffer,
    losses: wgpu::Buffer,
    reliability_accum: wgpu::Buffer,
    moments: wgpu::Buffer,
    counters: wgpu::Buffer,
    /// Both predictors' MLP weights as the register form reads them (storage for
    /// lane_stage.wgsl, uniform for infer_lane.wgsl); only in that form.
    lane_staged: Option<wgpu::Buffer>,
    /// The grid mirror the register form reads (grid_textures.rs).
    grid: Option<grid_textures::GridTextures>,
    sparse: Option<SparseBuffers>,
}

/// Bind groups that depend on neither the caller's buffers nor the call's parameters.
struct FixedBindGroups {
    reliability_update: wgpu::BindGroup,
    lane_stage: Option<wgpu::BindGroup>,
}

/// The neural incident radiance cache on the GPU.
pub struct NeuralCache {
    pub config: NircCacheSettings,
    pub bounds: SceneBounds,
    pub layout: ParameterLayout,
    pub placement: WeightPlacement,
    pipelines: Pipelines,
    buffers: Buffers,
    groups: FixedBindGroups,
}

/// Invocations per workgroup of every pass.
pub const WORKGROUP_SIZE: u32 = 64;

fn groups_for(threads: u64) -> u32 {
    threads.div_ceil(WORKGROUP_SIZE as u64).clamp(1, 65535) as u32
}

fn bind(
    gpu: &Gpu,
    label: &str,
    pipeline: &wgpu::ComputePipeline,
    entries: &[(u32, &wgpu::Buffer)],
) -> wgpu::BindGroup {
    bind_with_views(gpu, label, pipeline, entries, &[])
}

/// `bind` with storage-texture views as well (the grid mirror, grid_textures.rs).
fn bind_with_views(
    gpu: &Gpu,
    label: &str,
    pipeline: &wgpu::ComputePipeline,
    entries: &[(u32, &wgpu::Buffer)],
    views: &[(u32, &wgpu::TextureView)],
) -> wgpu::BindGroup {
    let entries: Vec<wgpu::BindGroupEntry> = entries
        .iter()
        .map(|&(binding, b)| wgpu::BindGroupEntry { binding, resource: b.as_entire_binding() })
        .chain(views.iter().map(|&(binding, v)| wgpu::BindGroupEntry {
            binding,
            resource: wgpu::BindingResource::TextureView(v),
        }))
        .collect();
    gpu.device.create_bind_group(&wgpu::BindGroupDescriptor {
        label: Some(label),
        layout: &pipeline.get_bind_group_layout(0),
        entries: &entries,
    })
}

fn dispatch(
    pass: &mut wgpu::ComputePass,
    pipeline: &wgpu::ComputePipeline,
    group: &wgpu::BindGroup,
    workgroups: u32,
) {
    pass.set_pipeline(pipeline);
    pass.set_bind_group(0, group, &[]);
    pass.dispatch_workgroups(workgroups, 1, 1);
}

/// A storage buffer holding `records` (for tests, benchmarks and callers without their own).
pub fn upload<T: Pod>(gpu: &Gpu, label: &str, items: &[T]) -> wgpu::Buffer {
    gpu.buffer_init(
        label,
        bytemuck::cast_slice(items),
        wgpu::BufferUsages::STORAGE | wgpu::BufferUsages::COPY_SRC | wgpu::BufferUsages::COPY_DST,
    )
}

/// The first `n` answers of an answer buffer, read back.
pub fn read_answers(
    gpu: &Gpu,
    answers: &wgpu::Buffer,
    n: u32,
) -> Result<Vec<CacheAnswer>, NircError> {
    let mut all: Vec<CacheAnswer> = read_pod(gpu, answers, "nirc answers")?;
    all.truncate(n as usize);
    Ok(all)
}

/// An output buffer for `n` answers.
pub fn answer_buffer(gpu: &Gpu, n: u32) -> wgpu::Buffer {
    gpu.device.create_buffer(&wgpu::BufferDescriptor {
        label: Some("nirc answers"),
        size: (n as u64 * std::mem::size_of::<CacheAnswer>() as u64).max(16),
        usage: wgpu::BufferUsages::STORAGE | wgpu::BufferUsages::COPY_SRC,
        mapped_at_creation: false,
    })
}

impl NeuralCache {
    /// The per-call parameters live in their own small buffer, so that several calls can be
    /// recorded into one command encoder.
    fn call_buffer(gpu: &Gpu, call: Call) -> wgpu::Buffer {
        gpu.buffer_init("nirc call", bytemuck::bytes_of(&call), wgpu::BufferUsages::STORAGE)
    }

    fn check_items(what: &str, buffer: &wgpu::Buffer, n: u32, item: u64) -> Result<(), NircError> {
        let needed = n as u64 * item;
        if buffer.size() < needed {
            return Err(NircError::BufferTooSmall {
                what: what.into(),
                bytes: buffer.size(),
                needed,
                count: n,
            });
        }
        Ok(())
    }

    /// Whether the passes read the hash grid from its texture mirror (grid_textures.rs).
    pub fn reads_grid_mirror(&self) -> bool {
        self.buffers.grid.is_some()
    }

    /// The grid mirror's two views at `bindings` ([High-LR, EMA]); none without the mirror.
    fn grid_views(&self, bindings: [u32; 2]) -> Vec<(u32, &wgpu::TextureView)> {
        self.buffers
            .grid
            .iter()
            .flat_map(|g| [(bindings[0], &g.views[0]), (bindings[1], &g.views[1])])
            .collect()
    }

    /// With sparse grid updates, how many grid quads the last training step touched (0
    /// without them).
    pub fn touched_grid_quads(&self, gpu: &Gpu) -> Result<u32, NircError> {
        let Some(sb) = &self.buffers.sparse else { return Ok(0) };
        let len: Vec<u32> = read_pod(gpu, &sb.touched_len, "nirc touched grid quad count")?;
        Ok(len[0])
    }

    pub fn counters(&self, gpu: &Gpu) -> Result<Counters, NircError> {
        let counters: Vec<Counters> = read_pod(gpu, &self.buffers.counters, "nirc counters")?;
        counters.first().copied().ok_or_else(|| NircError::Readback {
            what: "nirc counters".into(),
            reason: "the buffer is smaller than Counters".into(),
        })
    }

    /// Mean loss of the last training step's first `n` records (before that step's update).
    pub fn last_loss(&self, gpu: &Gpu, n: u32) -> Result<f64, NircError> {
        let losses: Vec<f32> = read_pod(gpu, &self.buffers.losses, "nirc losses")?;
        let n = (n as usize).min(losses.len());
        Ok(losses[..n].iter().map(|&l| l as f64).sum::<f64>() / n.max(1) as f64)
    }

    /// The whole state, read back from the GPU.
    pub fn download_state(&self, gpu: &Gpu) -> Result<CacheState, NircError> {
        let b = &self.buffers;
        let n = self.layout.total_params as usize;
        let read = |buf: &wgpu::Buffer, what: &str, len: usize| -> Result<Vec<f32>, NircError> {
            Ok(read_pod(gpu, buf, what)?[..len].to_vec())
        };
        Ok(CacheState {
            config: self.config.clone(),
            bounds: self.bounds,
            params: read(&b.params, "nirc params", n)?,
            ema: read(&b.ema, "nirc ema", n)?,
            adam_m: read(&b.adam_m, "nirc adam m", n)?,
            adam_v: read(&b.adam_v, "nirc adam v", n)?,
            counters: self.counters(gpu)?,
            reliability: read(
                &b.moments,
                "nirc reliability moments",
                cell_count(&self.config.reliability) as usize * MOMENTS_PER_CELL,
            )?,
            grid_steps: match &b.sparse {
                Some(sb) => read_pod::<u32>(gpu, &sb.grid_steps, "nirc grid step counts")?
                    [..CacheState::grid_steps_len(&self.config, &self.layout)]
                    .to_vec(),
                None => Vec::new(),
            },
        })
    }

    /// Writes the whole state (weights, EMA weights, Adam moments, counters, reliability grid).
    pub fn save(&self, gpu: &Gpu, path: &Path) -> Result<(), NircError> {
        self.download_state(gpu)?.save(path)
    }

    /// A cache continuing exactly from a saved state.
    pub fn load(gpu: &Gpu, path: &Path) -> Result<Self, NircError> {
        Self::from_state(gpu, &CacheState::load(path)?, None)
    }

    /// Convenience for callers holding records on the CPU: uploads and trains.
    pub fn train_records(&self, gpu: &Gpu, records: &[TrainingRecord]) -> Result<(), NircError> {
        self.train(gpu, &upload(gpu, "nirc training records", records), records.len() as u32)
    }

    /// Convenience: uploads queries, infers and reads the answers back.
    pub fn infer_queries(
        &self,
        gpu: &Gpu,
        queries: &[CacheQuery],
        mode: PredictorMode,
    ) -> Result<Vec<CacheAnswer>, NircError> {
        let n = queries.len() as u32;
        let out = answer_buffer(gpu, n);
        self.infer(gpu, &upload(gpu, "nirc queries", queries), n, &out, mode)?;
        read_answers(gpu, &out, n)
    }
}
