//! Reading GPU buffers back to the CPU: a copy into a MAP_READ staging buffer, then a blocking
//! map. Every readback goes through here: [`read_pod`] for one buffer, [`copy_all`] for several
//! in one submission, [`Staging`] where the copy is recorded into a pass's own encoder or the
//! staging buffer is kept from frame to frame.

use bytemuck::Pod;

use crate::error::RenderError;
use crate::gpu::Gpu;

/// A copy of the whole of `buffer` (COPY_SRC) in its own submission, read back as `T`s.
pub fn read_pod<T: Pod>(
    gpu: &Gpu,
    buffer: &wgpu::Buffer,
    what: &str,
) -> Result<Vec<T>, RenderError> {
    let [staging] = copy_all(gpu, [(buffer, what)]);
    staging.read(gpu)
}

/// Copies of the whole of each buffer, all in one submission; read each with [`Staging::read`].
pub fn copy_all<const N: usize>(gpu: &Gpu, sources: [(&wgpu::Buffer, &str); N]) -> [Staging; N] {
    let mut encoder = gpu
        .device
        .create_command_encoder(&wgpu::CommandEncoderDescriptor { label: Some("readback") });
    let staging = sources.map(|(buffer, what)| Staging::copy_of(gpu, &mut encoder, buffer, what));
    gpu.queue.submit([encoder.finish()]);
    staging
}

/// A MAP_READ buffer that a copy lands in; `what` names it in errors.
pub struct Staging {
    buffer: wgpu::Buffer,
    what: String,
}

impl Staging {
    pub fn new(gpu: &Gpu, what: &str, size: u64) -> Self {
        let buffer = gpu.device.create_buffer(&wgpu::BufferDescriptor {
            label: Some(what),
            size,
            usage: wgpu::BufferUsages::MAP_READ | wgpu::BufferUsages::COPY_DST,
            mapped_at_creation: false,
        });
        Self { buffer, what: what.into() }
    }

    /// A staging buffer the size of `source`, with the copy of all of it recorded in `encoder`.
    pub fn copy_of(
        gpu: &Gpu,
        encoder: &mut wgpu::CommandEncoder,
        source: &wgpu::Buffer,
        what: &str,
    ) -> Self {
        let staging = Self::new(gpu, what, source.size());
        staging.record(encoder, source, 0);
        staging
    }

    /// Records the copy of this buffer's size from `source`, starting at byte `offset`.
    pub fn record(&self, encoder: &mut wgpu::CommandEncoder, source: &wgpu::Buffer, offset: u64) {
        encoder.copy_buffer_to_buffer(source, offset, &self.buffer, 0, self.buffer.size());
    }

    /// Copies the start of `source` in its own submission and reads it back.
    pub fn read_from<T: Pod>(
        &self,
        gpu: &Gpu,
        source: &wgpu::Buffer,
    ) -> Result<Vec<T>, RenderError> {
        let mut encoder = gpu
            .device
            .create_command_encoder(&wgpu::CommandEncoderDescriptor { label: Some(&self.what) });
        self.record(&mut encoder, source, 0);
        gpu.queue.submit([encoder.finish()]);
        self.read(gpu)
    }

    /// Waits for the copy (already submitted) and reads the buffer as `T`s.
    pub fn read<T: Pod>(&self, gpu: &Gpu) -> Result<Vec<T>, RenderError> {
        read_buffer(gpu, &self.buffer)
            .map_err(|reason| RenderError::Readback { what: self.what.clone(), reason })
    }
}

/// Maps `buffer` (MAP_READ), copies it out as whole `T`s and unmaps it; the mapping step of
/// [`Staging::read`]. Trailing bytes that make no whole `T` are dropped. The mapped bytes carry
/// no alignment guarantee for `T`, so they are copied into a `Vec<T>` rather than cast in place.
pub fn read_buffer<T: Pod>(gpu: &Gpu, buffer: &wgpu::Buffer) -> Result<Vec<T>, String> {
    let (tx, rx) = std::sync::mpsc::channel();
    buffer.map_async(wgpu::MapMode::Read, .., move |r| {
        let _ = tx.send(r);
    });
    gpu.device.poll(wgpu::PollType::wait_indefinitely()).map_err(|e| e.to_string())?;
    rx.recv().map_err(|e| e.to_string())?.map_err(|e| e.to_string())?;
    let out = {
        let view = buffer.get_mapped_range(..).map_err(|e| e.to_string())?;
        let size = size_of::<T>();
        let n = view.len() / size;
        let mut values = vec![T::zeroed(); n];
        bytemuck::cast_slice_mut::<T, u8>(&mut values).copy_from_slice(&view[..n * size]);
        values
    };
    buffer.unmap();
    Ok(out)
}
