//! Building a cache on the GPU: the weight placement, every pass's pipelines, the buffers of the
//! whole state and the bind groups that never change.

use super::shaders::{self, CHUNK, WeightPlacement};
use super::{
    Buffers, FixedBindGroups, Hyper, NeuralCache, Pipelines, SparseBuffers, WORKGROUP_SIZE, bind,
    grid_textures, lane,
};
use crate::bounds::SceneBounds;
use crate::config::NircCacheSettings;
use crate::error::NircError;
use crate::layout::ParameterLayout;
use crate::records::ReliabilitySample;
use crate::reliability::{MOMENTS_PER_CELL, cell_count};
use crate::state::CacheState;
use render::gpu::Gpu;

/// u32 words per reliability cell accumulator (24 sums x 3 words + count).
const ACCUM_PER_CELL: u64 = 73;

/// Words of the touched bitmask per block of touched_list.wgsl (its BLOCK_WORDS: 4 per thread).
const TOUCHED_BLOCK_WORDS: u64 = 4 * WORKGROUP_SIZE as u64;

/// A storage buffer of `bytes` (at least 16), copyable both ways, its size checked first.
pub(crate) fn storage(gpu: &Gpu, label: &str, bytes: u64) -> Result<wgpu::Buffer, NircError> {
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
    Ok(gpu.checked_buffer_init(
        label,
        data,
        wgpu::BufferUsages::STORAGE | wgpu::BufferUsages::COPY_SRC | wgpu::BufferUsages::COPY_DST,
    )?)
}

impl NeuralCache {
    /// A fresh cache (initial weights from `config.seed`) over `scene_bounds`.
    pub fn new(
        gpu: &Gpu,
        config: &NircCacheSettings,
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
        let grid_width = (placement == WeightPlacement::Registers)
            .then(|| grid_textures::width_for(gpu, &layout))
            .flatten();
        let pipelines = Self::pipelines(gpu, &config, &layout, placement, grid_width)?;
        let buffers = Self::buffers(gpu, &config, &layout, state, placement, grid_width)?;
        let groups = Self::fixed_groups(gpu, &pipelines, &buffers);
        Ok(Self { bounds: state.bounds, config, layout, placement, pipelines, buffers, groups })
    }

    /// Every pass's pipelines, validated (render::compute): a shader the driver refuses is an
    /// error naming the pass.
    fn pipelines(
        gpu: &Gpu,
        config: &NircCacheSettings,
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

    fn hyper(config: &NircCacheSettings, bounds: &SceneBounds) -> Hyper {
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
        config: &NircCacheSettings,
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
        let mut counters = state.counters;
        counters.flag = 0;
        Ok(Buffers {
            hyper: gpu.buffer_init(
                "nirc hyper",
                bytemuck::bytes_of(&Self::hyper(config, &state.bounds)),
                wgpu::BufferUsages::STORAGE | wgpu::BufferUsages::COPY_DST,
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
        config: &NircCacheSettings,
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
}
