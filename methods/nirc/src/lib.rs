//! Neural incident radiance cache (NIRC) with reliability-weighted blending
//! (../shared/seeds/reliability-weighted-nirc.txt): a multi-resolution hash-grid encoding and a
//! tiny MLP trained online with Adam on relative L2, a debiased EMA copy of the weights, and a
//! hashed voxel grid of target/prediction moments whose correlations decide, per query, how much
//! to trust the fast (High-LR) predictor versus its EMA.
//!
//! - `cpu`: plain-Rust reference of every step (the ground truth of the tests).
//! - `gpu`: the same in WGSL compute passes (`NeuralCache`), shaders in `methods/nirc/shaders/`.
//! - `state`: the whole cache state and its file format (warm starts).

pub mod bounds;
pub mod config;
pub mod cpu;
pub mod error;
pub mod fixed_sum;
pub mod gpu;
pub mod integrator;
pub mod layout;
pub mod optimizer_config;
pub mod plugin;
pub mod recorded;
pub mod records;
pub mod reliability;
pub mod sigma_regions;
pub mod state;

pub use bounds::SceneBounds;
pub use config::{NircCacheSettings, PredictorMode};
pub use cpu::cache::{CpuCache, StepReport};
pub use error::NircError;
pub use gpu::NeuralCache;
pub use integrator::{CacheOutput, CachePathSettings, CachePaths};
pub use records::{CacheAnswer, CacheQuery, ReliabilitySample, TrainingRecord};
pub use state::CacheState;
