//! The WGSL path tracer: per frame, HDR radiance and a primary-hit G-buffer read back to the
//! CPU, GPU time per pass; and converged references accumulated in bounded batches.
//!
//! Shaders: render/shaders/path_tracer.wgsl (+ pt_sampling, pt_bsdf, pt_lights), concatenated
//! after the scene geometry interface (`SceneGeometry::WGSL`, bind group 1). This pass's own
//! bindings are group 0: the `Frame` uniform, materials, texture atlas, light table, the
//! radiance sum and the G-buffer.

use crate::bvh::SceneGeometry;
use crate::compute;
use crate::error::RenderError;
use crate::frame::{CameraBasis, FrameParams, GpuFrame};
use crate::gpu::Gpu;
use crate::lights::{LightTable, build_light_table};
use crate::materials::pack_materials;
use crate::readback::read_buffer;
use crate::scene::SceneChanges;
use crate::scene::{Camera, SceneDesc};
use crate::timing::{PassTimer, PassTiming, merge};
use bytemuck::{Pod, Zeroable};
use glam::Vec3;
use wgpu::util::DeviceExt;

/// `Hit::instance`/`primitive` of a pixel whose primary ray left the scene.
pub const NO_HIT: u32 = u32::MAX;

/// Paths (pixels x samples) one dispatch may trace, so that no submission runs long enough to
/// trip a GPU watchdog (about 2 s on desktop drivers) even on slow adapters.
pub const PATHS_PER_DISPATCH: u64 = 1 << 20;

/// Samples one invocation of the trace pass traces; a dispatch spreads its samples over
/// workgroup z (see trace_main in path_tracer.wgsl for why invocations must stay short).
pub const SAMPLES_PER_THREAD: u32 = 2;

/// Upper bound on sample chunks (workgroups along z) per dispatch.
const MAX_CHUNKS: u32 = 4096;

/// The pass names in [`FrameOutput::timings`].
pub const GBUFFER_PASS: &str = "gbuffer";
pub const PATH_TRACE_PASS: &str = "path_trace";

const WORKGROUP: u32 = 8;
/// Storage buffers of group 0 (materials, texels, lights, radiance, G-buffer, sample partials,
/// ray counter).
const STORAGE_BUFFERS: u32 = 7;
/// Words of the ray counter: [0] rays traced since the last clear.
const COUNTER_WORDS: u64 = 4;

/// Storage buffers a pass built on [`PathTracer::library_source`] binds before its own:
/// @group(0) (scene) and @group(1) (geometry). Add the pass's own to check the adapter limit.
pub const LIBRARY_STORAGE_BUFFERS: u32 = STORAGE_BUFFERS + crate::bvh::SceneGeometry::STORAGE_BUFFERS;
/// Storage buffers of scene_geometry.wgsl (group 1).
const GEOMETRY_STORAGE_BUFFERS: u32 = 8;

#[derive(Clone, Copy, Debug, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
pub struct PathTracerSettings {
    pub width: u32,
    pub height: u32,
    /// Maximum number of scattering events: 1 = direct lighting only.
    pub max_depth: u32,
    /// Russian roulette applies to bounces from this depth on (1 = after the first bounce).
    pub rr_start_depth: u32,
}

/// Primary-hit attributes of the pixel-centre ray, row-major, `width * height` each.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct GBuffer {
    /// Distance from the camera to the hit along the ray; `f32::INFINITY` on a miss.
    pub depth: Vec<f32>,
    /// World shading normal turned towards the camera; zero on a miss.
    pub normal: Vec<[f32; 3]>,
    /// Linear base colour at the hit (texture included); zero on a miss.
    pub albedo: Vec<[f32; 3]>,
    /// Pixel offset from where the point is now to where it was in the previous rendered frame
    /// (previous camera and instance transform); x right, y down. Misses: the offset of the
    /// direction at infinity (camera rotation only).
    pub motion: Vec<[f32; 2]>,
    /// Index into `SceneDesc::instances`; [`NO_HIT`] on a miss.
    pub instance_id: Vec<u32>,
    /// Triangle index in the instance's mesh; [`NO_HIT`] on a miss.
    pub primitive_id: Vec<u32>,
}

#[derive(Clone, Debug, Default, PartialEq)]
pub struct FrameOutput {
    pub width: u32,
    pub height: u32,
    /// Linear HDR radiance, mean of the frame's samples, row-major; alpha = 1.
    pub radiance: Vec<[f32; 4]>,
    pub gbuffer: GBuffer,
    /// One entry per pass: [`GBUFFER_PASS`], [`PATH_TRACE_PASS`] (readback excluded).
    pub timings: Vec<PassTiming>,
    /// Rays traced by both passes (G-buffer rays + camera, shadow and bounce rays of the paths),
    /// counted on the GPU.
    pub rays: u64,
    /// Paths shaded: pixels x spp.
    pub shaded: u64,
}

#[repr(C)]
#[derive(Clone, Copy, Pod, Zeroable)]
struct GpuGBufferTexel {
    normal: [f32; 3],
    depth: f32,
    albedo: [f32; 3],
    instance: u32,
    motion: [f32; 2],
    primitive: u32,
    _pad: u32,
}

const _: () = assert!(size_of::<GpuGBufferTexel>() == 48);

/// Bytes per pixel of the per-pixel buffers (radiance sum and G-buffer texel).
const BYTES_PER_PIXEL: u64 = 16 + size_of::<GpuGBufferTexel>() as u64;

pub struct PathTracer {
    settings: PathTracerSettings,
    geometry: SceneGeometry,
    layout: wgpu::BindGroupLayout,
    /// Passes built on the shading library, by (pass, source, own group, entry points).
    shared_passes: std::sync::Mutex<std::collections::HashMap<u64, (wgpu::BindGroupLayout, Vec<wgpu::ComputePipeline>)>>,
    trace_pipeline: wgpu::ComputePipeline,
    gbuffer_pipeline: wgpu::ComputePipeline,
    frame_buffer: wgpu::Buffer,
    materials: wgpu::Buffer,
    texels: wgpu::Buffer,
    lights: wgpu::Buffer,
    radiance_sum: wgpu::Buffer,
    gbuffer: wgpu::Buffer,
    /// Per-(chunk, pixel) sums of one dispatch, summed by `accumulate_main`.
    sample_partials: wgpu::Buffer,
    accumulate_pipeline: wgpu::ComputePipeline,
    max_chunks: u32,
    radiance_readback: wgpu::Buffer,
    gbuffer_readback: wgpu::Buffer,
    bind_group: wgpu::BindGroup,
    timer: PassTimer,
    /// Rays traced (atomic, flushed once per invocation), cleared per frame.
    counters: wgpu::Buffer,
    counters_readback: wgpu::Buffer,
    light_table: LightTable,
    camera: Camera,
    /// Camera before the last `update` (motion vectors), like the instances' previous
    /// transforms; the current camera before the first update.
    previous_camera: Camera,
    environment: Vec3,
    paths_per_dispatch: u64,
}

impl PathTracer {
    pub fn new(gpu: &Gpu, scene: &SceneDesc, settings: PathTracerSettings) -> Result<Self, RenderError> {
        if settings.max_depth == 0 {
            return Err(RenderError::Settings("max_depth must be at least 1 (1 = direct lighting)".into()));
        }
        gpu.check_resolution(settings.width, settings.height, BYTES_PER_PIXEL)?;
        let needed = STORAGE_BUFFERS + GEOMETRY_STORAGE_BUFFERS;
        let limit = gpu.limits.max_storage_buffers_per_shader_stage;
        if needed > limit {
            return Err(crate::gpu::GpuError::OverLimit {
                what: "storage buffers of the path tracer pass".into(),
                requested: needed as u64,
                limit: limit as u64,
                adapter: gpu.summary.name.clone(),
            }
            .into());
        }
        // No workgroup memory is declared (var<workgroup>): nothing to check against the budget.
        gpu.check_workgroup_memory("path_trace", 0)?;

        let geometry = SceneGeometry::new(gpu, scene)?;
        let (materials, texels) = pack_materials(scene)?;
        let light_table = build_light_table(scene)?;
        let device = &gpu.device;
        let storage = |label: &str, contents: &[u8]| -> Result<wgpu::Buffer, RenderError> {
            gpu.check_buffer_size(label, contents.len() as u64)?;
            Ok(device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
                label: Some(label),
                contents,
                usage: wgpu::BufferUsages::STORAGE | wgpu::BufferUsages::COPY_DST,
            }))
        };
        let materials = storage("materials", bytemuck::cast_slice(&materials))?;
        let texels = storage("base-colour texels", bytemuck::cast_slice(&texels))?;
        let lights = storage("lights", bytemuck::cast_slice(&light_table.lights))?;
        let pixels = settings.width as u64 * settings.height as u64;
        let per_pixel = |label: &str, size: u64, usage: wgpu::BufferUsages| {
            device.create_buffer(&wgpu::BufferDescriptor { label: Some(label), size, usage, mapped_at_creation: false })
        };
        let rw = wgpu::BufferUsages::STORAGE | wgpu::BufferUsages::COPY_SRC;
        let readback = wgpu::BufferUsages::MAP_READ | wgpu::BufferUsages::COPY_DST;
        let radiance_size = pixels * 16;
        let gbuffer_size = pixels * size_of::<GpuGBufferTexel>() as u64;
        let radiance_sum = per_pixel("radiance sum", radiance_size, rw);
        let gbuffer = per_pixel("gbuffer", gbuffer_size, rw);
        let radiance_readback = per_pixel("radiance readback", radiance_size, readback);
        let gbuffer_readback = per_pixel("gbuffer readback", gbuffer_size, readback);
        let max_chunks = MAX_CHUNKS.min(gpu.limits.max_compute_workgroups_per_dimension);
        let sample_partials = Self::partials_buffer(gpu, pixels, Self::chunks_for(PATHS_PER_DISPATCH, pixels, max_chunks))?;
        let frame_buffer = per_pixel("path tracer frame", size_of::<GpuFrame>() as u64, wgpu::BufferUsages::UNIFORM | wgpu::BufferUsages::COPY_DST);
        let counters = per_pixel("path tracer ray counter", COUNTER_WORDS * 4, rw | wgpu::BufferUsages::COPY_DST);
        let counters_readback = per_pixel("path tracer ray counter readback", COUNTER_WORDS * 4, readback);

        let layout = bind_group_layout(gpu);
        let [trace_pipeline, gbuffer_pipeline, accumulate_pipeline] =
            compute::pipelines(gpu, "path_tracer.wgsl", Self::shader_source(), &[&layout, geometry.bind_group_layout()], ["trace_main", "gbuffer_main", "accumulate_main"])?;

        let bind_group = compute::buffer_group(gpu, "path tracer", &layout, &[&frame_buffer, &materials, &texels, &lights, &radiance_sum, &gbuffer, &sample_partials, &counters]);
        Ok(Self {
            settings,
            geometry,
            layout,
            shared_passes: Default::default(),
            trace_pipeline,
            gbuffer_pipeline,
            frame_buffer,
            materials,
            texels,
            lights,
            radiance_sum,
            gbuffer,
            sample_partials,
            accumulate_pipeline,
            max_chunks,
            radiance_readback,
            gbuffer_readback,
            bind_group,
            timer: PassTimer::new(gpu, &[GBUFFER_PASS, PATH_TRACE_PASS]),
            counters,
            counters_readback,
            light_table,
            camera: scene.camera,
            previous_camera: scene.camera,
            environment: scene.environment,
            paths_per_dispatch: PATHS_PER_DISPATCH,
        })
    }

    /// The complete WGSL of the pass (geometry interface + path tracer): part of the key of
    /// anything cached from its images.
    pub fn shader_source() -> &'static str {
        static SOURCE: std::sync::OnceLock<String> = std::sync::OnceLock::new();
        SOURCE.get_or_init(|| {
            [
                Self::library_source(),
                &format!("const SAMPLES_PER_THREAD: u32 = {SAMPLES_PER_THREAD}u;"),
                include_str!("../shaders/path_tracer.wgsl"),
            ]
            .join("\n")
        })
    }

    /// The shading library without entry points: scene geometry (@group(1)), sampling, BSDFs,
    /// lights, the scene bindings (@group(0)) and the path integrator (`next_event`,
    /// `emitted_radiance`, `path_radiance`). Another method's pass appends its own WGSL (its
    /// buffers in @group(2)) and binds [`Self::scene_bind_group`] and the geometry's group.
    pub fn library_source() -> &'static str {
        static SOURCE: std::sync::OnceLock<String> = std::sync::OnceLock::new();
        SOURCE.get_or_init(|| {
            [
                SceneGeometry::WGSL,
                include_str!("../shaders/pt_sampling.wgsl"),
                include_str!("../shaders/pt_bsdf.wgsl"),
                include_str!("../shaders/pt_lights.wgsl"),
                include_str!("../shaders/pt_scene.wgsl"),
                include_str!("../shaders/pt_integrator.wgsl"),
            ]
            .join("\n")
        })
    }

    /// Group 0 over the current buffers, after one of them was replaced.
    fn rebind(&mut self, gpu: &Gpu) {
        let buffers = [&self.frame_buffer, &self.materials, &self.texels, &self.lights, &self.radiance_sum, &self.gbuffer, &self.sample_partials, &self.counters];
        self.bind_group = compute::buffer_group(gpu, "path tracer", &self.layout, &buffers);
    }

    /// The layout of a pass's own @group(2) (buffer kinds by binding) and the pipelines of
    /// `entries` in `source`, a WGSL module built on [`Self::library_source`] (scene @group(0),
    /// geometry @group(1)). Refuses a pass with more storage buffers than the adapter binds.
    pub fn library_pass<const N: usize>(
        &self,
        gpu: &Gpu,
        pass: &str,
        source: &str,
        own: &[wgpu::BufferBindingType],
        entries: [&str; N],
    ) -> Result<(wgpu::BindGroupLayout, [wgpu::ComputePipeline; N]), RenderError> {
        let own_storage = own.iter().filter(|k| matches!(k, wgpu::BufferBindingType::Storage { .. })).count() as u32;
        let needed = LIBRARY_STORAGE_BUFFERS + own_storage;
        let limit = gpu.limits.max_storage_buffers_per_shader_stage;
        if needed > limit {
            return Err(crate::gpu::GpuError::OverLimit { what: format!("storage buffers of pass '{pass}'"), requested: needed as u64, limit: limit as u64, adapter: gpu.summary.name.clone() }.into());
        }
        // Methods of one run share the pipelines of equal passes (three sample caches, two hash
        // caches): fewer compiled shaders, and on llvmpipe a working set that stays inside its
        // shader-variant cache, whose evictions cost seconds of recompilation per frame.
        let key = {
            use std::hash::{Hash, Hasher};
            let mut h = std::collections::hash_map::DefaultHasher::new();
            (pass, source, format!("{own:?}"), entries.as_slice()).hash(&mut h);
            h.finish()
        };
        let mut shared = self.shared_passes.lock().unwrap_or_else(|e| e.into_inner());
        if let Some((layout, pipelines)) = shared.get(&key)
            && let Ok(pipelines) = <[wgpu::ComputePipeline; N]>::try_from(pipelines.clone())
        {
            return Ok((layout.clone(), pipelines));
        }
        let layout = compute::buffer_layout(gpu, pass, own);
        let pipelines = compute::pipelines(gpu, pass, source, &[&self.layout, self.geometry.bind_group_layout(), &layout], entries)?;
        shared.insert(key, (layout.clone(), pipelines.to_vec()));
        Ok((layout, pipelines))
    }

    /// Layout of @group(0) of [`Self::library_source`].
    pub fn scene_bind_group_layout(&self) -> &wgpu::BindGroupLayout {
        &self.layout
    }

    /// @group(0) of [`Self::library_source`]. It changes when `update` had to grow a buffer:
    /// fetch it every frame, do not keep it.
    pub fn scene_bind_group(&self) -> &wgpu::BindGroup {
        &self.bind_group
    }

    /// Writes the frame uniform for another method's pass (camera, previous camera, lights,
    /// `spp` and the first sample index in `size.zw`, seed, frame, max depth) exactly as this
    /// tracer's own passes see it.
    pub fn prepare_frame(&self, gpu: &Gpu, spp: u32, first_sample: u32, seed: u64, frame: u32) {
        self.write_frame(gpu, &self.previous_camera, spp, first_sample, seed, frame, false);
    }

    /// The camera of the current frame (after the last `update`).
    pub fn camera(&self) -> &Camera {
        &self.camera
    }

    pub fn settings(&self) -> PathTracerSettings {
        self.settings
    }

    pub fn geometry(&self) -> &SceneGeometry {
        &self.geometry
    }

    /// Refreshes the dynamic parts: instance transforms, materials (and textures), lights
    /// (emissive triangles follow their instances), camera, environment. Meshes are fixed at
    /// `new`. Call once per simulated frame: the camera and instance transforms it replaces become
    /// the previous ones of motion vectors.
    pub fn update(&mut self, gpu: &Gpu, scene: &SceneDesc) {
        if let Err(e) = self.try_update(gpu, scene) {
            panic!("PathTracer::update: {e}");
        }
    }

    /// [`Self::update`] that reports an inconsistent scene instead of panicking.
    pub fn try_update(&mut self, gpu: &Gpu, scene: &SceneDesc) -> Result<(), RenderError> {
        self.update_changed(gpu, scene, SceneChanges::ALL)
    }

    /// [`Self::try_update`] that uploads only what `changes` names: materials and texels when
    /// materials changed, the light table when lights, instances (emissive triangles follow
    /// them) or materials changed. Instance transforms and the camera are taken every frame:
    /// they become the previous ones of motion vectors.
    pub fn update_changed(&mut self, gpu: &Gpu, scene: &SceneDesc, changes: SceneChanges) -> Result<(), RenderError> {
        let materials = (changes.materials || changes.geometry).then(|| pack_materials(scene)).transpose()?;
        let light_table = (changes.lights || changes.instances || changes.materials || changes.geometry).then(|| build_light_table(scene)).transpose()?;
        self.geometry.try_update_instances(gpu, &scene.instances)?;
        let mut rebind = false;
        let mut uploads: Vec<(&mut wgpu::Buffer, &str, &[u8])> = Vec::new();
        if let Some((materials, texels)) = &materials {
            uploads.push((&mut self.materials, "materials", bytemuck::cast_slice::<_, u8>(materials)));
            uploads.push((&mut self.texels, "base-colour texels", bytemuck::cast_slice(texels)));
        }
        if let Some(table) = &light_table {
            uploads.push((&mut self.lights, "lights", bytemuck::cast_slice(&table.lights)));
        }
        for (buffer, label, bytes) in uploads {
            if buffer.size() == bytes.len() as u64 {
                gpu.queue.write_buffer(buffer, 0, bytes);
            } else {
                gpu.check_buffer_size(label, bytes.len() as u64)?;
                *buffer = gpu.device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
                    label: Some(label),
                    contents: bytes,
                    usage: wgpu::BufferUsages::STORAGE | wgpu::BufferUsages::COPY_DST,
                });
                rebind = true;
            }
        }
        if rebind {
            self.rebind(gpu);
        }
        if let Some(table) = light_table {
            self.light_table = table;
        }
        self.previous_camera = self.camera;
        self.camera = scene.camera;
        self.environment = scene.environment;
        Ok(())
    }

    /// One frame: G-buffer of the pixel-centre rays, then `spp` jittered paths per pixel.
    pub fn render(&mut self, gpu: &Gpu, spp: u32, seed: u64, frame: u32) -> Result<FrameOutput, RenderError> {
        if spp == 0 {
            return Err(RenderError::Settings("spp must be at least 1".into()));
        }
        let previous = self.previous_camera;
        // G-buffer pass.
        self.write_frame(gpu, &previous, 0, 0, seed, frame, false);
        let mut timed = self.timer.begin(gpu, "gbuffer");
        timed.encoder().clear_buffer(&self.counters, 0, None);
        timed.pass(0, |pass| {
            pass.set_pipeline(&self.gbuffer_pipeline);
            pass.set_bind_group(0, &self.bind_group, &[]);
            pass.set_bind_group(1, self.geometry.bind_group(), &[]);
            pass.dispatch_workgroups(self.settings.width.div_ceil(WORKGROUP), self.settings.height.div_ceil(WORKGROUP), 1);
        })?;
        let mut timings = timed.submit()?;

        // Path-trace pass, in batches of bounded work.
        merge(&mut timings, self.trace_batches(gpu, &previous, spp, seed, frame, &mut |_, _| {})?);

        let radiance = self.read_radiance(gpu)?;
        let gbuffer = self.read_gbuffer(gpu)?;
        let rays = self.read_rays(gpu)?;
        let shaded = self.settings.width as u64 * self.settings.height as u64 * spp as u64;
        Ok(FrameOutput { width: self.settings.width, height: self.settings.height, radiance, gbuffer, timings, rays, shaded })
    }

    /// The current scene accumulated to `spp` samples per pixel in batches of at most
    /// [`PATHS_PER_DISPATCH`] paths, one submission each; `progress(done_spp, total_spp)` after
    /// every batch. Radiance only (no G-buffer).
    pub fn render_reference(&mut self, gpu: &Gpu, spp: u32, seed: u64, frame: u32, progress: &mut dyn FnMut(u32, u32)) -> Result<Vec<[f32; 4]>, RenderError> {
        if spp == 0 {
            return Err(RenderError::Settings("reference spp must be at least 1".into()));
        }
        let previous = self.previous_camera;
        self.trace_batches(gpu, &previous, spp, seed, frame, progress)?;
        self.read_radiance(gpu)
    }

    /// Samples per pixel in one dispatch at this resolution (at least 1).
    pub fn samples_per_dispatch(&self) -> u32 {
        let pixels = self.settings.width as u64 * self.settings.height as u64;
        Self::chunks_for(self.paths_per_dispatch, pixels, self.max_chunks) * SAMPLES_PER_THREAD
    }

    /// Changes the work bound of one dispatch (default [`PATHS_PER_DISPATCH`]): lower it for a
    /// slow adapter with a watchdog, raise it for a fast one. The image does not depend on it
    /// beyond float summation order.
    pub fn set_paths_per_dispatch(&mut self, gpu: &Gpu, paths: u64) -> Result<(), RenderError> {
        self.paths_per_dispatch = paths.max(1);
        let pixels = self.settings.width as u64 * self.settings.height as u64;
        let chunks = Self::chunks_for(self.paths_per_dispatch, pixels, self.max_chunks);
        if self.sample_partials.size() < pixels * chunks as u64 * 16 {
            self.sample_partials = Self::partials_buffer(gpu, pixels, chunks)?;
            self.rebind(gpu);
        }
        Ok(())
    }

    /// Chunks of [`SAMPLES_PER_THREAD`] samples per dispatch: at least one.
    fn chunks_for(paths: u64, pixels: u64, max_chunks: u32) -> u32 {
        (paths / pixels / SAMPLES_PER_THREAD as u64).clamp(1, max_chunks as u64) as u32
    }

    fn partials_buffer(gpu: &Gpu, pixels: u64, chunks: u32) -> Result<wgpu::Buffer, RenderError> {
        let size = pixels * chunks as u64 * 16;
        gpu.check_buffer_size("sample partials", size)?;
        Ok(gpu.device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("sample partials"),
            size,
            usage: wgpu::BufferUsages::STORAGE,
            mapped_at_creation: false,
        }))
    }

    /// Traces `spp` samples into the radiance sum; returns the summed time of the batches.
    fn trace_batches(&self, gpu: &Gpu, previous: &Camera, spp: u32, seed: u64, frame: u32, progress: &mut dyn FnMut(u32, u32)) -> Result<Vec<PassTiming>, RenderError> {
        let per_dispatch = self.samples_per_dispatch();
        let mut done = 0;
        let mut timings = Vec::new();
        while done < spp {
            let batch = per_dispatch.min(spp - done);
            self.write_frame(gpu, previous, batch, done, seed, frame, done > 0);
            let mut timed = self.timer.begin(gpu, "path trace");
            timed.pass(1, |pass| {
                let (x, y) = (self.settings.width.div_ceil(WORKGROUP), self.settings.height.div_ceil(WORKGROUP));
                pass.set_bind_group(0, &self.bind_group, &[]);
                pass.set_bind_group(1, self.geometry.bind_group(), &[]);
                pass.set_pipeline(&self.trace_pipeline);
                pass.dispatch_workgroups(x, y, batch.div_ceil(SAMPLES_PER_THREAD));
                pass.set_pipeline(&self.accumulate_pipeline);
                pass.dispatch_workgroups(x, y, 1);
            })?;
            merge(&mut timings, timed.submit()?);
            done += batch;
            progress(done, spp);
        }
        Ok(timings)
    }

    #[allow(clippy::too_many_arguments)]
    fn write_frame(&self, gpu: &Gpu, previous: &Camera, spp: u32, first_sample: u32, seed: u64, frame: u32, accumulate: bool) {
        let (w, h) = (self.settings.width, self.settings.height);
        let params = FrameParams {
            camera: CameraBasis::new(&self.camera, w, h),
            previous_camera: CameraBasis::new(previous, w, h),
            environment: self.environment,
            emitter_weight: self.light_table.emitter_weight,
            width: w,
            height: h,
            spp,
            first_sample,
            seed,
            frame,
            max_depth: self.settings.max_depth,
            rr_start_depth: self.settings.rr_start_depth,
            analytic_lights: self.light_table.analytic,
            emitters: self.light_table.emitters,
            accumulate,
        };
        gpu.queue.write_buffer(&self.frame_buffer, 0, bytemuck::bytes_of(&params.gpu()));
    }

    /// Rays the passes since the last clear traced (the frame's G-buffer and paths).
    fn read_rays(&self, gpu: &Gpu) -> Result<u64, RenderError> {
        let mut encoder = gpu.device.create_command_encoder(&wgpu::CommandEncoderDescriptor { label: Some("ray counter readback") });
        encoder.copy_buffer_to_buffer(&self.counters, 0, &self.counters_readback, 0, COUNTER_WORDS * 4);
        gpu.queue.submit([encoder.finish()]);
        let words: Vec<u32> = read_buffer(gpu, &self.counters_readback).map_err(|reason| RenderError::Readback { what: "ray counter".into(), reason })?;
        Ok(words[0] as u64)
    }

    fn read_radiance(&self, gpu: &Gpu) -> Result<Vec<[f32; 4]>, RenderError> {
        let mut encoder = gpu.device.create_command_encoder(&wgpu::CommandEncoderDescriptor { label: Some("radiance readback") });
        encoder.copy_buffer_to_buffer(&self.radiance_sum, 0, &self.radiance_readback, 0, self.radiance_sum.size());
        gpu.queue.submit([encoder.finish()]);
        let sums: Vec<[f32; 4]> = read_buffer(gpu, &self.radiance_readback).map_err(|reason| RenderError::Readback { what: "radiance".into(), reason })?;
        // w holds the sample count: the mean is sum / count.
        Ok(sums.into_iter().map(|s| if s[3] > 0.0 { [s[0] / s[3], s[1] / s[3], s[2] / s[3], 1.0] } else { [0.0, 0.0, 0.0, 1.0] }).collect())
    }

    fn read_gbuffer(&self, gpu: &Gpu) -> Result<GBuffer, RenderError> {
        let mut encoder = gpu.device.create_command_encoder(&wgpu::CommandEncoderDescriptor { label: Some("gbuffer readback") });
        encoder.copy_buffer_to_buffer(&self.gbuffer, 0, &self.gbuffer_readback, 0, self.gbuffer.size());
        gpu.queue.submit([encoder.finish()]);
        let texels: Vec<GpuGBufferTexel> = read_buffer(gpu, &self.gbuffer_readback).map_err(|reason| RenderError::Readback { what: "gbuffer".into(), reason })?;
        let mut g = GBuffer::default();
        for t in texels {
            g.depth.push(if t.instance == NO_HIT { f32::INFINITY } else { t.depth });
            g.normal.push(t.normal);
            g.albedo.push(t.albedo);
            g.motion.push(t.motion);
            g.instance_id.push(t.instance);
            g.primitive_id.push(t.primitive);
        }
        Ok(g)
    }
}

/// Group 0 of the path tracer and of every pass built on its shading library (the scene):
/// frame uniform, materials, texels, lights, then the path tracer's own radiance sum, G-buffer,
/// sample partials and ray counter.
const SCENE_GROUP: [wgpu::BufferBindingType; 8] = {
    let read = wgpu::BufferBindingType::Storage { read_only: true };
    let write = wgpu::BufferBindingType::Storage { read_only: false };
    [wgpu::BufferBindingType::Uniform, read, read, read, write, write, write, write]
};

fn bind_group_layout(gpu: &Gpu) -> wgpu::BindGroupLayout {
    compute::buffer_layout(gpu, "path tracer", &SCENE_GROUP)
}

