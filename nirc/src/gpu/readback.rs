//! Copying a GPU buffer back to the CPU (blocking).

use crate::error::NircError;
use render::gpu::Gpu;

pub fn read_bytes(gpu: &Gpu, buffer: &wgpu::Buffer, what: &str) -> Result<Vec<u8>, NircError> {
    let size = buffer.size();
    let staging = gpu.device.create_buffer(&wgpu::BufferDescriptor {
        label: Some("nirc readback"),
        size,
        usage: wgpu::BufferUsages::MAP_READ | wgpu::BufferUsages::COPY_DST,
        mapped_at_creation: false,
    });
    let mut encoder = gpu.device.create_command_encoder(&wgpu::CommandEncoderDescriptor { label: Some("nirc readback") });
    encoder.copy_buffer_to_buffer(buffer, 0, &staging, 0, size);
    gpu.queue.submit([encoder.finish()]);
    let (tx, rx) = std::sync::mpsc::channel();
    staging.map_async(wgpu::MapMode::Read, .., move |r| {
        let _ = tx.send(r);
    });
    let fail = |reason: String| NircError::Readback { what: what.into(), reason };
    gpu.device.poll(wgpu::PollType::wait_indefinitely()).map_err(|e| fail(e.to_string()))?;
    rx.recv().map_err(|e| fail(e.to_string()))?.map_err(|e| fail(e.to_string()))?;
    let data = staging.get_mapped_range(..).map_err(|e| fail(e.to_string()))?.to_vec();
    staging.unmap();
    Ok(data)
}

pub fn read_f32(gpu: &Gpu, buffer: &wgpu::Buffer, what: &str) -> Result<Vec<f32>, NircError> {
    let bytes = read_bytes(gpu, buffer, what)?;
    Ok(bytes.chunks_exact(4).map(|c| f32::from_le_bytes(c.try_into().unwrap())).collect())
}

/// Blocks until the GPU has finished everything submitted (for timing).
pub fn wait_idle(gpu: &Gpu) -> Result<(), NircError> {
    gpu.device.poll(wgpu::PollType::wait_indefinitely()).map(|_| ()).map_err(|e| NircError::Readback { what: "device idle".into(), reason: e.to_string() })
}
