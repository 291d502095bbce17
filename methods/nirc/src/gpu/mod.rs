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
pub mod lane;
pub mod readback;
pub mod shaders;

use crate::bounds::SceneBounds;
use crate::config::{NircConfig, PredictorMode};
use crate::cpu::optimizer::Counters;
use crate::error::NircError;
use crate::layout::ParameterLayout;
use crate::records::{CacheAnswer, CacheQuery, ReliabilitySample, TrainingRecord};
use crate::reliability::{MOMENTS_PER_CELL, cell_count};
use crate::state::CacheState;
use bytemuck::Pod;
use render::gpu::Gpu;
use render::readback::read_pod;
use render::timing::TimedFrame;
use shaders::{CHUNK, WORKGROUP_SIZE, WeightPlacement};
use std::path::Path;
use wgpu::util::DeviceExt;

/// `Call::mode` of the diagnostic reliability look-up (after the four `PredictorMode` codes).
const RELIABILITY_MODE: u32 = 4;

/// u32 words per reliability cell accumulator (24 sums x 3 words + count).
const ACCUM_PER_CELL: u64 = 73;

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

/// The bind groups of one training step ([`NeuralCache::prepare_step`]).
pub struct TrainStep {
    n: u32,
    num_chunks: u32,
    fb: wgpu::BindGroup,
    accumulate: wgpu::BindGroup,
    walk: wgpu::BindGroup,
    partial: Option<wgpu::BindGroup>,
    reduce: wgpu::BindGroup,
    check: wgpu::BindGroup,
    apply: wgpu::BindGroup,
    ema: wgpu::BindGroup,
    finish: wgpu::BindGroup,
    /// With sparse grid updates, the groups of adam_sparse.wgsl's passes (as `Pipelines::sparse`).
    sparse: Option<[wgpu::BindGroup; 7]>,
}

/// How many workgroups a dispatch runs: a count, or what the GPU wrote into a buffer.
#[derive(Clone, Copy)]
enum Groups<'a> {
    Direct(u32),
    Indirect(&'a wgpu::Buffer),
}

/// One dispatch of a training step: name (for the profile), pipeline, bind group, workgroups.
type Stage<'a> = (&'static str, &'a wgpu::ComputePipeline, &'a wgpu::BindGroup, Groups<'a>);

/// Bind groups that depend on neither the caller's buffers nor the call's parameters.
struct FixedBindGroups {
    reliability_update: wgpu::BindGroup,
    lane_stage: Option<wgpu::BindGroup>,
}

/// The neural incident radiance cache on the GPU.
pub struct NeuralCache {
    pub config: NircConfig,
    pub bounds: SceneBounds,
    pub layout: ParameterLayout,
    pub placement: WeightPlacement,
    pipelines: Pipelines,
    buffers: Buffers,
    groups: FixedBindGroups,
}

/// Parameter quads each invocation of Adam's and the EMA's passes updates (their loops stride
/// over the whole vector): the per-invocation work (the step's bias corrections and the flag,
/// read from `counters`) is then paid once per 4 quads. On lavapipe one quad per invocation
/// made these passes 1.3-1.6x slower (docs/lab/nirc-speed.md); 16 was slower again.
const PARAM_QUADS_PER_INVOCATION: u64 = 4;

/// Words of the touched bitmask per block of touched_list.wgsl (its BLOCK_WORDS: 4 per thread).
const TOUCHED_BLOCK_WORDS: u64 = 4 * WORKGROUP_SIZE as u64;

fn groups_for(threads: u64) -> u32 {
    threads.div_ceil(WORKGROUP_SIZE as u64).clamp(1, 65535) as u32
}

fn storage(gpu: &Gpu, label: &str, bytes: u64) -> Result<wgpu::Buffer, NircError> {
    gpu.check_buffer_size(label, bytes)?;
    Ok(gpu.device.create_buffer(&wgpu::BufferDescriptor {
        label: Some(label),
        size: bytes.max(16),
        usage: wgpu::BufferUsages::STORAGE
            | wgpu::BufferUsages::COPY_SRC
            | wgpu::BufferUsages::COPY_DST,
        mapped_at_creation: false,
    }))
}

fn storage_init(gpu: &Gpu, label: &str, data: &[u8]) -> Result<wgpu::Buffer, NircError> {
    gpu.check_buffer_size(label, data.len() as u64)?;
    Ok(gpu.device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
        label: Some(label),
        contents: data,
        usage: wgpu::BufferUsages::STORAGE
            | wgpu::BufferUsages::COPY_SRC
            | wgpu::BufferUsages::COPY_DST,
    }))
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
    gpu.device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
        label: Some(label),
        contents: bytemuck::cast_slice(items),
        usage: wgpu::BufferUsages::STORAGE
            | wgpu::BufferUsages::COPY_SRC
            | wgpu::BufferUsages::COPY_DST,
    })
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
    /// A fresh cache (initial weights from `config.seed`) over `scene_bounds`.
    pub fn new(
        gpu: &Gpu,
        config: &NircConfig,
        scene_bounds: SceneBounds,
    ) -> Result<Self, NircError> {
        Self::from_state(gpu, &CacheState::initial(config, scene_bounds)?, None)
    }

    /// Uploads a whole state. `placement` None takes `FLICKER_NIRC_MLP` if set, else chooses the
    /// register-form inference on a CPU adapter and the tiled MLP on others where the network
    /// and the adapter allow them, else the per-record passes.
    pub fn from_state(
        gpu: &Gpu,
        state: &CacheState,
        placement: Option<WeightPlacement>,
    ) -> Result<Self, NircError> {
        let config = state.config.clone();
        config.validate()?;
        let layout = ParameterLayout::new(&config);
        let tiled = || -> Result<(), NircError> {
            if let Some(why) = shaders::tiled_unsupported(&layout) {
                return Err(NircError::Config(format!(
                    "the tiled MLP cannot run this network: {why}"
                )));
            }
            // Only a network the tiles take has a tile shape (a width of 5 has none).
            Ok(gpu.check_workgroup_memory(
                "nirc tiled MLP (tiles in workgroup memory)",
                shaders::workgroup_bytes(&layout),
            )?)
        };
        // The register form trains with the tiled pass, so it also needs `tiled`.
        let registers = || -> Result<(), NircError> {
            tiled()?;
            Ok(gpu.check_uniform_size("nirc register-form inference (both predictors' MLP weights in one uniform binding)", lane::uniform_bytes(&layout) as u64)?)
        };
        let placement = match placement.or(WeightPlacement::from_env()?) {
            Some(WeightPlacement::Tiled) => {
                tiled()?;
                WeightPlacement::Tiled
            }
            Some(WeightPlacement::Registers) => {
                registers()?;
                WeightPlacement::Registers
            }
            Some(WeightPlacement::Storage) => WeightPlacement::Storage,
            None if gpu.summary.device_type == "Cpu" && registers().is_ok() => {
                WeightPlacement::Registers
            }
            None if tiled().is_ok() => WeightPlacement::Tiled,
            None => WeightPlacement::Storage,
        };
        if placement == WeightPlacement::Storage {
            // A network too large for the driver's per-invocation loop cap would come out wrong
            // silently (llvmpipe); refuse it with the numbers instead.
            gpu.check_loop_iterations(
                &format!(
                    "nirc training/inference (width {}, {} hidden layers)",
                    config.network.width, config.network.hidden_layers
                ),
                layout.loop_iterations_per_invocation(WORKGROUP_SIZE),
            )?;
        }
        if config.max_batch.div_ceil(WORKGROUP_SIZE)
            > gpu.limits.max_compute_workgroups_per_dimension
        {
            return Err(NircError::Config(format!(
                "max_batch {} needs more workgroups than this adapter dispatches",
                config.max_batch
            )));
        }
        let grid_width = grid_textures::width_for(gpu, &layout, placement);
        let pipelines = Self::pipelines(gpu, &config, &layout, placement, grid_width)?;
        let buffers = Self::buffers(gpu, &config, &layout, state, placement, grid_width)?;
        let groups = Self::fixed_groups(gpu, &pipelines, &buffers);
        Ok(Self { bounds: state.bounds, config, layout, placement, pipelines, buffers, groups })
    }

    /// Every pass's pipelines, validated (render::compute): a shader the driver refuses is an
    /// error naming the pass.
    fn pipelines(
        gpu: &Gpu,
        config: &NircConfig,
        layout: &ParameterLayout,
        placement: WeightPlacement,
        grid_width: Option<u32>,
    ) -> Result<Pipelines, NircError> {
        let build = |pass: &str,
                     entries: &[&str]|
         -> Result<Vec<wgpu::ComputePipeline>, NircError> {
            let source = shaders::program(config, layout, pass, grid_width);
            let label = format!("nirc {pass}");
            Ok(match entries {
                [a] => render::compute::pipelines_auto_layout(gpu, &label, &source, [*a])?.to_vec(),
                [a, b] => {
                    render::compute::pipelines_auto_layout(gpu, &label, &source, [*a, *b])?.to_vec()
                }
                [a, b, c] => {
                    render::compute::pipelines_auto_layout(gpu, &label, &source, [*a, *b, *c])?
                        .to_vec()
                }
                _ => unreachable!("one to three entry points per module"),
            })
        };
        let one = |pass: &str| -> Result<wgpu::ComputePipeline, NircError> {
            Ok(build(pass, &["main"])?.remove(0))
        };
        let [weight_partial, weight_reduce] = <[wgpu::ComputePipeline; 2]>::try_from(build(
            "weight_gradient",
            &["partial_sums", "reduce"],
        )?)
        .expect("two pipelines");
        let [adam_check, adam_apply, ema_update] = <[wgpu::ComputePipeline; 3]>::try_from(build(
            "adam_ema",
            &["check", "apply", "ema_update"],
        )?)
        .expect("three pipelines");
        let tiled = placement.tiled_training();
        let sparse = if config.optimizer.sparse_grid {
            let [clear, check, apply, ema] = render::compute::pipelines_auto_layout(
                gpu,
                "nirc adam_sparse",
                &shaders::program(config, layout, "adam_sparse", grid_width),
                ["clear_touched", "check_grid", "apply_grid", "ema_grid"],
            )?;
            let [count, scan, emit] = render::compute::pipelines_auto_layout(
                gpu,
                "nirc touched_list",
                &shaders::program(config, layout, "touched_list", grid_width),
                ["count_blocks", "scan_blocks", "emit_list"],
            )?;
            Some([clear, check, apply, ema, count, scan, emit])
        } else {
            None
        };
        Ok(Pipelines {
            train: one(if tiled { "train_tile" } else { "train_forward_backward" })?,
            weight_partial: (!tiled).then_some(weight_partial),
            weight_reduce,
            adam_check,
            adam_apply,
            ema_update,
            reliability_accumulate: one("reliability_accumulate")?,
            reliability_update: one("reliability_update")?,
            reliability_walk: one("reliability_walk")?,
            finish_step: one("finish_step")?,
            infer: one(match placement {
                WeightPlacement::Tiled => "infer_tile",
                WeightPlacement::Registers => "infer_lane",
                WeightPlacement::Storage => "infer",
            })?,
            lane_stage: (placement == WeightPlacement::Registers)
                .then(|| one("lane_stage"))
                .transpose()?,
            sparse,
        })
    }

    fn hyper(config: &NircConfig, bounds: &SceneBounds) -> Hyper {
        let inv = bounds.inv_extent();
        Hyper {
            bounds_min: [bounds.min[0], bounds.min[1], bounds.min[2], 0.0],
            inv_extent: [inv[0], inv[1], inv[2], 0.0],
            learning_rate: config.optimizer.learning_rate,
            beta1: config.optimizer.beta1,
            beta2: config.optimizer.beta2,
            adam_epsilon: config.optimizer.epsilon,
            alpha: config.ema.alpha,
            loss_epsilon: config.loss.epsilon,
            lambda: config.reliability.lambda,
            reliability_epsilon: config.reliability.epsilon,
            kappa: config.reliability.kappa,
            warmup: config.reliability.warmup,
            reliability_resolution: config.reliability.resolution,
            loss_luminance: (config.loss.normalization
                == crate::config::LossNormalization::Luminance) as u32,
            moments_per_sample: (config.reliability.update
                == crate::config::MomentUpdate::PerSample) as u32,
            pad0: 0,
            pad1: 0,
            pad2: 0,
        }
    }

    fn buffers(
        gpu: &Gpu,
        config: &NircConfig,
        layout: &ParameterLayout,
        state: &CacheState,
        placement: WeightPlacement,
        grid_width: Option<u32>,
    ) -> Result<Buffers, NircError> {
        let n = layout.total_params as usize;
        for (name, len, expected) in [
            ("params", state.params.len(), n),
            ("ema", state.ema.len(), n),
            ("adam_m", state.adam_m.len(), n),
            ("adam_v", state.adam_v.len(), n),
            (
                "reliability",
                state.reliability.len(),
                cell_count(&config.reliability) as usize * MOMENTS_PER_CELL,
            ),
            ("grid_steps", state.grid_steps.len(), CacheState::grid_steps_len(config, layout)),
        ] {
            if len != expected {
                return Err(NircError::Config(format!(
                    "state.{name} has {len} values, the config needs {expected}"
                )));
            }
        }
        let max_batch = config.max_batch as u64;
        let chunks = max_batch.div_ceil(CHUNK as u64);
        let parameters = |label: &str, data: &[u8]| {
            gpu.device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
                label: Some(label),
                contents: data,
                usage: wgpu::BufferUsages::STORAGE | wgpu::BufferUsages::COPY_DST,
            })
        };
        let mut counters = state.counters;
        counters.flag = 0;
        Ok(Buffers {
            hyper: parameters(
                "nirc hyper",
                bytemuck::bytes_of(&Self::hyper(config, &state.bounds)),
            ),
            params: storage_init(gpu, "nirc params", bytemuck::cast_slice(&state.params))?,
            ema: storage_init(gpu, "nirc ema params", bytemuck::cast_slice(&state.ema))?,
            adam_m: storage_init(gpu, "nirc adam m", bytemuck::cast_slice(&state.adam_m))?,
            adam_v: storage_init(gpu, "nirc adam v", bytemuck::cast_slice(&state.adam_v))?,
            grad: storage(gpu, "nirc mlp gradient", layout.mlp_params as u64 * 4)?,
            partials: storage(
                gpu,
                "nirc gradient partial sums",
                chunks * layout.mlp_params as u64 * 4,
            )?,
            scratch: storage(
                gpu,
                "nirc training scratch",
                max_batch * layout.scratch_stride() as u64 * 4,
            )?,
            grid_accum: storage(
                gpu,
                "nirc hash-grid gradient sums",
                layout.grid_params() as u64 * 12,
            )?,
            samples: storage(
                gpu,
                "nirc reliability samples",
                max_batch * std::mem::size_of::<ReliabilitySample>() as u64,
            )?,
            sample_cells: storage(gpu, "nirc reliability sample cells and links", max_batch * 8)?,
            losses: storage(gpu, "nirc losses", max_batch * 4)?,
            reliability_accum: storage(
                gpu,
                "nirc reliability sums",
                cell_count(&config.reliability) as u64 * ACCUM_PER_CELL * 4,
            )?,
            moments: storage_init(
                gpu,
                "nirc reliability moments",
                bytemuck::cast_slice(&state.reliability),
            )?,
            counters: storage_init(gpu, "nirc counters", bytemuck::bytes_of(&counters))?,
            lane_staged: (placement == WeightPlacement::Registers).then(|| {
                gpu.device.create_buffer(&wgpu::BufferDescriptor {
                    label: Some("nirc staged MLP weights"),
                    size: lane::uniform_bytes(layout) as u64,
                    usage: wgpu::BufferUsages::STORAGE | wgpu::BufferUsages::UNIFORM,
                    mapped_at_creation: false,
                })
            }),
            grid: grid_width.map(|w| grid_textures::GridTextures::new(gpu, layout, state, w)),
            sparse: Self::sparse_buffers(gpu, config, layout, state)?,
        })
    }

    fn sparse_buffers(
        gpu: &Gpu,
        config: &NircConfig,
        layout: &ParameterLayout,
        state: &CacheState,
    ) -> Result<Option<SparseBuffers>, NircError> {
        if !config.optimizer.sparse_grid {
            return Ok(None);
        }
        let quads = layout.grid_params() as u64 / 4;
        let words = quads.div_ceil(32);
        let blocks = words.div_ceil(TOUCHED_BLOCK_WORDS);
        let table = crate::cpu::optimizer::BiasPowers::new(&config.optimizer, &config.ema)?;
        Ok(Some(SparseBuffers {
            grid_steps: storage_init(
                gpu,
                "nirc grid step counts",
                bytemuck::cast_slice(&state.grid_steps),
            )?,
            bias_powers: storage_init(
                gpu,
                "nirc bias corrections by step",
                bytemuck::cast_slice(&table.rows),
            )?,
            touched: storage(gpu, "nirc touched grid quads", quads * 4)?,
            touched_bits: storage(gpu, "nirc touched grid quad bits", words * 4)?,
            touched_len: storage(gpu, "nirc touched grid quad count", 16)?,
            block_counts: storage(gpu, "nirc touched grid block counts", blocks * 4)?,
            block_offsets: storage(gpu, "nirc touched grid block offsets", blocks * 4)?,
            blocks: blocks as u32,
            list_dispatch: {
                gpu.check_buffer_size("nirc touched grid dispatch", 16)?;
                gpu.device.create_buffer(&wgpu::BufferDescriptor {
                    label: Some("nirc touched grid dispatch"),
                    size: 16,
                    usage: wgpu::BufferUsages::STORAGE | wgpu::BufferUsages::INDIRECT,
                    mapped_at_creation: false,
                })
            },
        }))
    }

    fn fixed_groups(gpu: &Gpu, p: &Pipelines, b: &Buffers) -> FixedBindGroups {
        FixedBindGroups {
            reliability_update: bind(
                gpu,
                "nirc reliability update",
                &p.reliability_update,
                &[(1, &b.hyper), (2, &b.reliability_accum), (3, &b.moments), (4, &b.counters)],
            ),
            lane_stage: p.lane_stage.as_ref().zip(b.lane_staged.as_ref()).map(|(stage, staged)| {
                bind(gpu, "nirc lane stage", stage, &[(3, &b.params), (4, &b.ema), (9, staged)])
            }),
        }
    }

    /// The per-call parameters live in their own small buffer, so that several calls can be
    /// recorded into one command encoder.
    fn call_buffer(gpu: &Gpu, call: Call) -> wgpu::Buffer {
        gpu.device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
            label: Some("nirc call"),
            contents: bytemuck::bytes_of(&call),
            usage: wgpu::BufferUsages::STORAGE,
        })
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

    /// One training step on the first `n` records of `records` (array of `TrainingRecord`),
    /// submitted at once. A step with a non-finite loss, gradient or weight is rolled back on
    /// the GPU and counted in `Counters::rejected_steps`.
    pub fn train(&self, gpu: &Gpu, records: &wgpu::Buffer, n: u32) -> Result<(), NircError> {
        let mut encoder = gpu
            .device
            .create_command_encoder(&wgpu::CommandEncoderDescriptor { label: Some("nirc train") });
        self.encode_train(gpu, &mut encoder, records, n)?;
        gpu.queue.submit([encoder.finish()]);
        Ok(())
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
        self.dispatch_adam(&mut pass, &step);
        self.dispatch_ema(&mut pass, &step);
        self.dispatch_reliability(&mut pass, &step);
        Ok(())
    }

    /// The bind groups and sizes of one training step on the first `n` of `records`; `None` for
    /// no records. Then [`Self::adam_timed`], [`Self::ema_timed`], [`Self::reliability_timed`]
    /// in this order, each its own pass (the frame's `nirc::train`, `nirc::ema` and
    /// `nirc::reliability_update` systems).
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

    /// Forward and backward passes, gradients and the Adam step of the High-LR weights (with the
    /// step's reliability samples accumulated), as pass `index` of a timed frame.
    pub fn adam_timed(
        &self,
        timed: &mut TimedFrame,
        index: usize,
        step: &TrainStep,
    ) -> Result<(), NircError> {
        self.clear_step(timed.encoder());
        timed.pass(index, |pass| self.dispatch_adam(pass, step))?;
        Ok(())
    }

    /// The debiased EMA of the weights after the Adam step, as pass `index` of a timed frame.
    pub fn ema_timed(
        &self,
        timed: &mut TimedFrame,
        index: usize,
        step: &TrainStep,
    ) -> Result<(), NircError> {
        timed.pass(index, |pass| self.dispatch_ema(pass, step))?;
        Ok(())
    }

    /// The reliability grid's moments from the step's samples, then the step's commit (or
    /// roll-back count), as pass `index` of a timed frame.
    pub fn reliability_timed(
        &self,
        timed: &mut TimedFrame,
        index: usize,
        step: &TrainStep,
    ) -> Result<(), NircError> {
        timed.pass(index, |pass| self.dispatch_reliability(pass, step))?;
        Ok(())
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

    /// The `nirc::reliability_update` part: the per-sample moment walk (not for the batch-mean
    /// rule), the grid's update, the step's commit.
    fn reliability_stages<'a>(&'a self, s: &'a TrainStep) -> Vec<Stage<'a>> {
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

    fn dispatch_adam(&self, pass: &mut wgpu::ComputePass, s: &TrainStep) {
        Self::dispatch_stages(pass, &self.adam_stages(s));
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
                let mut encoder = gpu
                    .device
                    .create_command_encoder(&wgpu::CommandEncoderDescriptor { label: Some(name) });
                record(&mut encoder);
                gpu.queue.submit([encoder.finish()]);
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
        for stage in self
            .adam_stages(&s)
            .into_iter()
            .chain(self.ema_stages(&s))
            .chain(self.reliability_stages(&s))
        {
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

    fn dispatch_ema(&self, pass: &mut wgpu::ComputePass, s: &TrainStep) {
        Self::dispatch_stages(pass, &self.ema_stages(s));
    }

    fn dispatch_reliability(&self, pass: &mut wgpu::ComputePass, s: &TrainStep) {
        Self::dispatch_stages(pass, &self.reliability_stages(s));
    }

    /// The bind groups of the reliability accumulation and walk over `samples`.
    fn reliability_groups(
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
        let mut encoder = gpu.device.create_command_encoder(&wgpu::CommandEncoderDescriptor {
            label: Some("nirc reliability"),
        });
        encoder.clear_buffer(&b.reliability_accum, 0, None);
        {
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
        }
        gpu.queue.submit([encoder.finish()]);
        Ok(())
    }

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
        let mut encoder = gpu
            .device
            .create_command_encoder(&wgpu::CommandEncoderDescriptor { label: Some("nirc infer") });
        self.encode_infer(gpu, &mut encoder, queries, n, out, mode)?;
        gpu.queue.submit([encoder.finish()]);
        Ok(())
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
