//! Errors of the render crate: every failure names what was asked and what was expected.

use crate::gpu::GpuError;

#[derive(Debug, thiserror::Error)]
pub enum RenderError {
    #[error(transparent)]
    Gpu(#[from] GpuError),
    #[error(transparent)]
    Bvh(#[from] crate::bvh::BvhError),
    /// A WGSL pass failed to compile or validate (a bug, or an adapter missing a capability).
    #[error("pass '{pass}': {message}")]
    Shader { pass: String, message: String },
    /// The scene description is inconsistent (an index out of range, an empty mesh, ...).
    #[error("invalid scene: {0}")]
    Scene(String),
    /// Mapping a buffer back to the CPU failed.
    #[error("reading back '{what}' from the GPU failed: {reason}")]
    Readback { what: String, reason: String },
    /// Invalid renderer settings (zero samples, zero depth, ...).
    #[error("invalid settings: {0}")]
    Settings(String),
}
