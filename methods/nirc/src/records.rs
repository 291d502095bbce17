//! What the path tracer hands the cache: training records and queries, declared once for Rust
//! and WGSL (`render::gpu_struct!`; 16-byte aligned vec4s).

use bytemuck::{Pod, Zeroable};
use render::gpu_struct::GpuStruct;

render::gpu_struct! {
    /// One Monte Carlo training sample: the cache should predict `target_rgb` (RGB incident
    /// radiance) at `position` from `direction` (unit). `.w` components are ignored, except that
    /// the path tracer marks a valid record with position.w = 1.
    #[derive(Default, PartialEq)]
    pub struct TrainingRecord {
        pub position: [f32; 4] => "vec4<f32>",
        pub direction: [f32; 4] => "vec4<f32>",
        pub target_rgb: [f32; 4] => "vec4<f32>",
    }
}

render::gpu_struct! {
    /// One cache query: world-space position and unit direction. `.w` components are ignored.
    #[derive(Default, PartialEq)]
    pub struct CacheQuery {
        pub position: [f32; 4] => "vec4<f32>",
        pub direction: [f32; 4] => "vec4<f32>",
    }
}

render::gpu_struct! {
    /// One sample of the reliability statistics: target y and both predictions at a position.
    #[derive(Default, PartialEq)]
    pub struct ReliabilitySample {
        pub position: [f32; 4] => "vec4<f32>",
        pub target_rgb: [f32; 4] => "vec4<f32>",
        pub f_cur: [f32; 4] => "vec4<f32>",
        pub f_ema: [f32; 4] => "vec4<f32>",
    }
}

/// The WGSL declarations of the records, queries and reliability samples.
pub fn wgsl() -> String {
    [TrainingRecord::WGSL, CacheQuery::WGSL, ReliabilitySample::WGSL].concat()
}

/// The answer to a query: `radiance` = max(0, L̂) in .xyz, and in .w the weight σ given to the
/// High-LR predictor (0 for EMA-only, 1 for High-LR only, 0 or 1 for the switch).
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, PartialEq, Pod, Zeroable)]
pub struct CacheAnswer {
    pub radiance: [f32; 3],
    pub sigma: f32,
}

impl TrainingRecord {
    pub fn new(position: [f32; 3], direction: [f32; 3], target: [f32; 3]) -> Self {
        Self {
            position: [position[0], position[1], position[2], 0.0],
            direction: [direction[0], direction[1], direction[2], 0.0],
            target_rgb: [target[0], target[1], target[2], 0.0],
        }
    }
    pub fn query(&self) -> CacheQuery {
        CacheQuery { position: self.position, direction: self.direction }
    }
}

impl CacheQuery {
    pub fn new(position: [f32; 3], direction: [f32; 3]) -> Self {
        Self {
            position: [position[0], position[1], position[2], 0.0],
            direction: [direction[0], direction[1], direction[2], 0.0],
        }
    }
}
