//! Errors of the cache: each names the file or setting and what was expected.

use render::gpu::GpuError;
use std::path::PathBuf;

#[derive(Debug, thiserror::Error)]
pub enum NircError {
    #[error("invalid NIRC setting {0}")]
    Config(String),
    #[error(transparent)]
    Gpu(#[from] GpuError),
    /// A pass built on the path tracer's shading library could not be made.
    #[error(transparent)]
    Render(#[from] render::error::RenderError),
    #[error("training batch of {requested} records is over the cache's max_batch of {max}")]
    BatchTooLarge { requested: u32, max: u32 },
    #[error("buffer '{what}' holds {bytes} bytes, {needed} needed for {count} items")]
    BufferTooSmall { what: String, bytes: u64, needed: u64, count: u32 },
    #[error("reading or writing the cache state file {path}: {source}")]
    Io { path: PathBuf, source: std::io::Error },
    #[error("cache state file {path} is not valid: {what}")]
    Format { path: PathBuf, what: String },
    #[error("reading back '{what}' from the GPU failed: {reason}")]
    Readback { what: String, reason: String },
}
