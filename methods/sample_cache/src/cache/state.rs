//! The cache's state read and written, and its stale-visibility audit (tests, diagnostics).

use super::SampleCache;
use crate::gpu_types::AUDIT_WORD;
use crate::output::CacheState;
use render::error::RenderError;
use render::gpu::Gpu;
use render::readback::read_pod;
use render::scene_gpu::SceneGpu;

impl SampleCache {
    /// Reads back the cache the last frame produced.
    pub fn read_state(&self, gpu: &Gpu) -> Result<CacheState, RenderError> {
        let cache = &self.caches[self.current];
        let masks = read_pod(gpu, &cache.mask, "ssc masks")?;
        let slots = read_pod(gpu, &cache.slots, "ssc slots")?;
        Ok(CacheState { masks, slots })
    }

    /// Replaces the cache the next frame reprojects (tests: a state built to exercise one
    /// decision). `state` must hold one mask per pixel and `slots` slots per pixel.
    pub fn write_state(&mut self, gpu: &Gpu, state: &CacheState) -> Result<(), RenderError> {
        let pixels = (self.width * self.height) as usize;
        let n = self.settings.slots as usize;
        if state.masks.len() != pixels || state.slots.len() != n * pixels {
            return Err(RenderError::Settings(format!(
                "sample cache state: {} masks and {} slots, expected {pixels} and {}",
                state.masks.len(),
                state.slots.len(),
                n * pixels
            )));
        }
        let cache = &self.caches[self.current];
        gpu.queue.write_buffer(&cache.mask, 0, bytemuck::cast_slice(&state.masks));
        gpu.queue.write_buffer(&cache.slots, 0, bytemuck::cast_slice(&state.slots));
        Ok(())
    }

    /// Stale visibility of the last frame: how many samples the cache holds as visible that a
    /// retrace from the current camera finds occluded (what `Multi` would correct). Traces one
    /// ray per visible sample; for tests and diagnostics, outside the timed passes.
    pub fn audit(&self, gpu: &Gpu, scene: &SceneGpu) -> Result<u32, RenderError> {
        let mut encoder = gpu
            .device
            .create_command_encoder(&wgpu::CommandEncoderDescriptor { label: Some("ssc audit") });
        encoder.clear_buffer(&self.work, AUDIT_WORD * 4, Some(4));
        {
            let mut pass = encoder.begin_compute_pass(&wgpu::ComputePassDescriptor {
                label: Some("audit"),
                timestamp_writes: None,
            });
            self.frame.bind(gpu, scene, &mut pass);
            // The bind group whose destination is the cache the last frame wrote.
            pass.set_bind_group(2, &self.bind_groups[1 - self.current], &[]);
            pass.set_pipeline(&self.pipelines.audit.get());
            pass.dispatch_workgroups(
                self.width.div_ceil(8),
                self.height.div_ceil(8),
                self.settings.slots,
            );
        }
        self.header_readback.record(&mut encoder, &self.work, 0);
        gpu.queue.submit([encoder.finish()]);
        let header: Vec<u32> = self.header_readback.read(gpu)?;
        Ok(header[AUDIT_WORD as usize])
    }
}
