//! GPU time per pass from timestamp queries (one begin/end pair per compute pass), with the
//! CPU wall time of the same work as a fallback and a cross-check.

use crate::gpu::Gpu;

/// Time of one pass of one frame.
#[derive(Clone, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct PassTiming {
    pub pass: String,
    /// From timestamp queries where `gpu.has_timestamps()`, else `None`.
    pub gpu_ms: Option<f64>,
    /// Wall time from encoding to the GPU finishing the pass's submission.
    pub cpu_ms: f64,
}

/// A query set with a begin/end pair for each of `passes` passes, and buffers to read it back.
pub struct PassTimestamps {
    query_set: wgpu::QuerySet,
    resolve: wgpu::Buffer,
    readback: wgpu::Buffer,
    passes: u32,
    period_ns: f64,
}

impl PassTimestamps {
    /// `None` where the adapter has no timestamp queries.
    pub fn new(gpu: &Gpu, passes: u32) -> Option<Self> {
        if !gpu.has_timestamps() || passes == 0 {
            return None;
        }
        let count = 2 * passes;
        let query_set = gpu.device.create_query_set(&wgpu::QuerySetDescriptor { label: Some("pass timestamps"), ty: wgpu::QueryType::Timestamp, count });
        let size = count as u64 * 8;
        let resolve = gpu.device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("timestamp resolve"),
            size,
            usage: wgpu::BufferUsages::QUERY_RESOLVE | wgpu::BufferUsages::COPY_SRC,
            mapped_at_creation: false,
        });
        let readback = gpu.device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("timestamp readback"),
            size,
            usage: wgpu::BufferUsages::MAP_READ | wgpu::BufferUsages::COPY_DST,
            mapped_at_creation: false,
        });
        Some(Self { query_set, resolve, readback, passes, period_ns: gpu.queue.get_timestamp_period() as f64 })
    }

    /// Timestamp writes bracketing pass number `pass`.
    pub fn writes(&self, pass: u32) -> wgpu::ComputePassTimestampWrites<'_> {
        assert!(pass < self.passes, "pass {pass} of {}", self.passes);
        wgpu::ComputePassTimestampWrites { query_set: &self.query_set, beginning_of_pass_write_index: Some(2 * pass), end_of_pass_write_index: Some(2 * pass + 1) }
    }

    /// Records the resolve and the copy to the readback buffer; call after the last pass.
    pub fn resolve(&self, encoder: &mut wgpu::CommandEncoder) {
        encoder.resolve_query_set(&self.query_set, 0..2 * self.passes, &self.resolve, 0);
        encoder.copy_buffer_to_buffer(&self.resolve, 0, &self.readback, 0, self.resolve.size());
    }

    /// Milliseconds of each pass; call after the submission holding `resolve` has completed.
    pub fn read(&self, gpu: &Gpu) -> Result<Vec<f64>, String> {
        let ticks: Vec<u64> = crate::readback::read_buffer(gpu, &self.readback)?;
        Ok(ticks.chunks_exact(2).map(|p| p[1].saturating_sub(p[0]) as f64 * self.period_ns * 1e-6).collect())
    }
}
