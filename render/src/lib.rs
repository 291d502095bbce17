//! GPU side: wgpu device, BVH upload (obvhs), WGSL passes, GPU timing, readback.

pub mod scene;
pub mod gpu;
pub mod bvh;
pub mod error;
