//! What the trial passes share (`MisPass`, `ClosedFormPass`): one invocation per seed of a
//! pipeline whose @group(0) is (params, seeds, results), a 2D dispatch, the results read
//! back.

use render::compute::buffer_group;
use render::gpu::Gpu;
use render::readback::Staging;

/// Runs `pipeline` over `seeds`; `T` is one trial's result as the shader writes it.
pub(super) fn run_trials<T: bytemuck::Pod>(
    gpu: &Gpu,
    label: &str,
    layout: &wgpu::BindGroupLayout,
    pipeline: &wgpu::ComputePipeline,
    params: &[u8],
    seeds: &[u32],
) -> Result<Vec<T>, String> {
    let device = &gpu.device;
    let params = gpu.buffer_init(label, params, wgpu::BufferUsages::STORAGE);
    let seeds_buf =
        gpu.buffer_init(label, bytemuck::cast_slice(seeds), wgpu::BufferUsages::STORAGE);
    let size = (seeds.len() * std::mem::size_of::<T>()) as u64;
    let results = device.create_buffer(&wgpu::BufferDescriptor {
        label: Some(label),
        size,
        usage: wgpu::BufferUsages::STORAGE | wgpu::BufferUsages::COPY_SRC,
        mapped_at_creation: false,
    });
    let group = buffer_group(gpu, label, layout, &[&params, &seeds_buf, &results]);
    let mut enc = device.create_command_encoder(&Default::default());
    {
        let mut pass = enc.begin_compute_pass(&Default::default());
        pass.set_pipeline(pipeline);
        pass.set_bind_group(0, &group, &[]);
        // 2D dispatch: 10^6 trials exceed 65535 workgroups of 64 on one axis.
        let groups = (seeds.len() as u32).div_ceil(64);
        let max = gpu.device.limits().max_compute_workgroups_per_dimension;
        pass.dispatch_workgroups(groups.min(max), groups.div_ceil(max), 1);
    }
    let staging = Staging::copy_of(gpu, &mut enc, &results, label);
    gpu.queue.submit([enc.finish()]);
    staging.read(gpu).map_err(|e| e.to_string())
}
