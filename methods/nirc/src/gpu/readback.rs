//! Waiting for the GPU (blocking). Buffers are read back with `render::readback`.

use crate::error::NircError;
use render::gpu::Gpu;

/// Blocks until the GPU has finished everything submitted (for timing).
pub fn wait_idle(gpu: &Gpu) -> Result<(), NircError> {
    gpu.device
        .poll(wgpu::PollType::wait_indefinitely())
        .map(|_| ())
        .map_err(|e| NircError::Readback { what: "device idle".into(), reason: e.to_string() })
}
