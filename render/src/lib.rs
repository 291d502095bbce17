//! GPU side: wgpu device, BVH upload (obvhs), WGSL passes, GPU timing, readback.

/// The plain-data scene (its own crate, shared with `sim`).
pub use ::scene;
pub mod bvh;
pub mod compute;
pub mod error;
pub mod frame;
pub mod frame_bindings;
pub mod gpu;
pub mod gpu_fault;
pub mod gpu_struct;
pub mod lights;
pub mod materials;
pub mod memory;
pub mod pass_library;
pub mod path_tracer;
pub mod readback;
pub mod scene_features;
pub mod scene_gpu;
pub mod scene_group;
pub mod shader;
pub mod texel_table;
pub mod timing;
