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
    let mut encoder = gpu
        .device
        .create_command_encoder(&wgpu::CommandEncoderDescriptor { label: Some("nirc readback") });
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

/// The buffer as whole values of `T` (trailing bytes that make no whole value are dropped). A
/// `Vec<u8>` carries no alignment guarantee for `T`, so the bytes are copied into a `Vec<T>`
/// rather than cast in place.
pub fn read_pod<T: bytemuck::Pod>(
    gpu: &Gpu,
    buffer: &wgpu::Buffer,
    what: &str,
) -> Result<Vec<T>, NircError> {
    let bytes = read_bytes(gpu, buffer, what)?;
    let size = std::mem::size_of::<T>();
    let n = bytes.len() / size;
    let mut values = vec![T::zeroed(); n];
    bytemuck::cast_slice_mut::<T, u8>(&mut values).copy_from_slice(&bytes[..n * size]);
    Ok(values)
}

pub fn read_f32(gpu: &Gpu, buffer: &wgpu::Buffer, what: &str) -> Result<Vec<f32>, NircError> {
    read_pod(gpu, buffer, what)
}

/// Blocks until the GPU has finished everything submitted (for timing).
pub fn wait_idle(gpu: &Gpu) -> Result<(), NircError> {
    gpu.device
        .poll(wgpu::PollType::wait_indefinitely())
        .map(|_| ())
        .map_err(|e| NircError::Readback { what: "device idle".into(), reason: e.to_string() })
}
