//! A method's frame parameters: its own `Frame` (a read-only storage buffer, as every pass's
//! parameters) and its own @group(0), those parameters next to the scene's shared tables
//! ([`SceneGpu`]). Each method (each renderer: the references, a test) owns one, so no dispatch
//! reads parameters another method wrote, whatever order their systems run in.

use std::sync::Mutex;

use crate::frame::Frame;
use crate::gpu::Gpu;
use crate::scene_gpu::SceneGpu;

pub struct FrameBindings {
    params: wgpu::Buffer,
    /// @group(0) and the scene generation it was made at: made again on the first bind after the
    /// scene reallocated a table.
    group: Mutex<(u64, wgpu::BindGroup)>,
}

impl FrameBindings {
    pub fn new(gpu: &Gpu, scene: &SceneGpu) -> Self {
        let params = gpu.device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("frame parameters"),
            size: size_of::<Frame>() as u64,
            usage: wgpu::BufferUsages::STORAGE | wgpu::BufferUsages::COPY_DST,
            mapped_at_creation: false,
        });
        let group = scene.bind_group(gpu, &params);
        Self { params, group: Mutex::new((scene.generation(), group)) }
    }

    /// Writes the parameters of this method's next dispatches on the scene as last uploaded:
    /// camera, previous camera, lights, `spp` and the first sample index, seed, frame, max depth.
    pub fn prepare(
        &self,
        gpu: &Gpu,
        scene: &SceneGpu,
        spp: u32,
        first_sample: u32,
        seed: u64,
        frame: u32,
    ) {
        self.write(gpu, scene, spp, first_sample, seed, frame, false);
    }

    /// [`Self::prepare`] with `accumulate`: the path tracer's later batches add to the radiance
    /// sum instead of replacing it.
    #[allow(clippy::too_many_arguments)]
    pub fn write(
        &self,
        gpu: &Gpu,
        scene: &SceneGpu,
        spp: u32,
        first_sample: u32,
        seed: u64,
        frame: u32,
        accumulate: bool,
    ) {
        let params = scene.frame_params(spp, first_sample, seed, frame, accumulate);
        gpu.queue.write_buffer(&self.params, 0, bytemuck::bytes_of(&params.gpu()));
    }

    /// @group(0) over these parameters and the scene's tables as they are now.
    pub fn bind_group(&self, gpu: &Gpu, scene: &SceneGpu) -> wgpu::BindGroup {
        let mut held = self.group.lock().unwrap_or_else(|e| e.into_inner());
        if held.0 != scene.generation() {
            *held = (scene.generation(), scene.bind_group(gpu, &self.params));
        }
        held.1.clone()
    }

    /// Sets @group(0) ([`Self::bind_group`]) and the geometry's @group(1) on `pass`.
    pub fn bind(&self, gpu: &Gpu, scene: &SceneGpu, pass: &mut wgpu::ComputePass<'_>) {
        pass.set_bind_group(0, &self.bind_group(gpu, scene), &[]);
        pass.set_bind_group(1, scene.geometry().bind_group(), &[]);
    }
}
