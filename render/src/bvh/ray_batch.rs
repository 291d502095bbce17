//! A compute pass that traces a buffer of rays through [`SceneGeometry`]: the WGSL traversal
//! made observable, for the traversal tests and the benchmark (which fills in another traversal
//! through [`RayBatch::with_traversal`]).

use glam::{Vec2, Vec3};

use super::{BvhError, Hit, SceneGeometry};
use crate::compute::BufferBinding;
use crate::gpu::Gpu;
use crate::gpu_struct::GpuStruct;
use crate::scene_features::SceneFeatures;
use crate::shader::Module;

const WORKGROUP_SIZE: u32 = 64;

/// One ray: `t` in units of `direction` (which need not be normalised).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct RayQuery {
    pub origin: Vec3,
    pub direction: Vec3,
    pub t_max: f32,
}

/// What `surface_point`, `previous_world_position` and `triangle_world_vertices` returned.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SurfaceRecord {
    pub position: Vec3,
    pub geometric_normal: Vec3,
    pub shading_normal: Vec3,
    pub uv: Vec2,
    pub material: u32,
    pub previous_position: Vec3,
    pub triangle: [Vec3; 3],
}

crate::gpu_struct! {
    struct GpuRay {
        origin: [f32; 3] => "vec3f",
        t_max: f32 => "f32",
        direction: [f32; 3] => "vec3f",
        pad: u32 => "u32",
    }
}

crate::gpu_struct! {
    struct GpuHit {
        t: f32 => "f32",
        instance: u32 => "u32",
        primitive: u32 => "u32",
        any_hit: u32 => "u32",
        barycentrics: [f32; 2] => "vec2f",
        pad: [f32; 2] => "vec2f",
    }
}

crate::gpu_struct! {
    struct GpuPoint {
        position: [f32; 4] => "vec4f",
        geometric_normal: [f32; 4] => "vec4f",
        shading_normal: [f32; 4] => "vec4f",
        uv: [f32; 2] => "vec2f",
        material: u32 => "u32",
        pad: u32 => "u32",
        previous_position: [f32; 4] => "vec4f",
        /// triangle_world_vertices
        triangle: [[f32; 4]; 3] => "array<vec4f, 3>",
    }
}

crate::gpu_struct! {
    struct BatchParams {
        count: u32 => "u32",
        row_pitch: u32 => "u32",
        pad: [u32; 2] => "vec2u",
    }
}

/// The pass's @group(0) (its geometry is @group(1)).
const GROUP: [BufferBinding; 4] = [
    BufferBinding::read("rays", "array<GpuRay>"),
    BufferBinding::read_write("hits", "array<GpuHit>"),
    BufferBinding::read_write("points", "array<GpuPoint>"),
    BufferBinding::read("params", "BatchParams"),
];

/// The structs of the pass, for the layout test.
pub fn struct_layout_mismatches() -> Vec<String> {
    use crate::gpu_struct::layout_mismatches;
    [
        layout_mismatches::<GpuRay>(""),
        layout_mismatches::<GpuHit>(""),
        layout_mismatches::<GpuPoint>(""),
        layout_mismatches::<BatchParams>(""),
    ]
    .concat()
}

/// Which kernel [`RayBatch::dispatch`] runs.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum TraceKind {
    Closest,
    Any,
    /// Attributes of the closest hits (run after `Closest`).
    SurfacePoints,
}

pub struct RayBatch {
    layout: wgpu::BindGroupLayout,
    closest: wgpu::ComputePipeline,
    any: wgpu::ComputePipeline,
    points: wgpu::ComputePipeline,
    /// Entries of the compiled traversal stack.
    stack: u32,
}

/// The geometry a batch traces through: the bind groups after the batch's own @group(0).
pub trait BatchGeometry {
    fn bind_groups(&self) -> Vec<&wgpu::BindGroup>;
    /// Entries the CWBVH traversal stack can need ([`SceneGeometry::stack_entries`]).
    fn stack_entries(&self) -> u32;
}

impl BatchGeometry for SceneGeometry {
    fn bind_groups(&self) -> Vec<&wgpu::BindGroup> {
        vec![self.bind_group()]
    }

    fn stack_entries(&self) -> u32 {
        SceneGeometry::stack_entries(self)
    }
}

/// Rays uploaded once, traced any number of times.
pub struct RayBuffers {
    count: u32,
    groups: (u32, u32),
    hits: wgpu::Buffer,
    points: wgpu::Buffer,
    bind_group: wgpu::BindGroup,
}

impl RayBatch {
    /// The batch of the CWBVH traversal (scene_geometry.wgsl), its stack sized for `geometry`:
    /// it traces geometry whose BVH needs no more ([`Self::dispatch`] checks).
    pub fn new(gpu: &Gpu, geometry: &SceneGeometry) -> Self {
        Self::with_traversal(
            gpu,
            SceneGeometry::modules(),
            crate::wgsl_file!("ray_batch/cwbvh.wgsl"),
            &[geometry.bind_group_layout()],
            geometry.stack_entries(),
        )
    }

    /// bvh_ray_batch.wgsl's kernels with `trace` as `package::ray_batch::trace`, on the
    /// geometry's `modules` bound at @group(1), ... (`layouts`), with a CWBVH stack for
    /// `stack_entries`. Only the stack is specialised: the kernels do not shade.
    pub fn with_traversal(
        gpu: &Gpu,
        modules: Vec<Module>,
        trace: Module,
        layouts: &[&wgpu::BindGroupLayout],
        stack_entries: u32,
    ) -> Self {
        let stack = SceneFeatures::stack_for(stack_entries);
        let features = SceneFeatures { traversal_stack: stack, ..SceneFeatures::ALL };
        let layout = crate::compute::binding_layout(gpu, "ray batch", &GROUP);
        let types = Module::generated(
            "package::ray_batch_types",
            &[GpuRay::WGSL, GpuHit::WGSL, GpuPoint::WGSL, BatchParams::WGSL],
        );
        let bindings =
            crate::compute::group_module("package::ray_batch_bindings", 0, &GROUP, &[&types]);
        let program = crate::shader::Program::new(modules)
            .with([types, bindings, trace.at("package::ray_batch::trace")])
            .entry(crate::wgsl_file!("bvh_ray_batch.wgsl"))
            .replacing(&features.module());
        let groups: Vec<&wgpu::BindGroupLayout> =
            [&layout].into_iter().chain(layouts.iter().copied()).collect();
        let [closest, any, points] = crate::compute::pipelines(
            gpu,
            "bvh_ray_batch.wgsl",
            &program,
            &groups,
            ["trace_closest_rays", "trace_any_rays", "surface_points"],
        )
        .unwrap_or_else(|e| panic!("the ray batch's WGSL: {e}"));
        Self { closest, any, points, layout, stack }
    }

    /// Entries of the traversal stack the batch was compiled with.
    pub fn stack_entries(&self) -> u32 {
        self.stack
    }

    /// Uploads the rays (refuses more than the adapter's buffers hold).
    pub fn upload(&self, gpu: &Gpu, rays: &[RayQuery]) -> Result<RayBuffers, BvhError> {
        let count = rays.len() as u32;
        let n = rays.len().max(1) as u64;
        for (what, stride) in [
            ("ray buffer", 32u64),
            ("hit buffer", 32),
            ("surface point buffer", size_of::<GpuPoint>() as u64),
        ] {
            gpu.check_buffer_size(what, n * stride)?;
        }
        let groups_needed = count.div_ceil(WORKGROUP_SIZE).max(1);
        let max = gpu.limits.max_compute_workgroups_per_dimension;
        let groups_x = groups_needed.min(max);
        let groups = (groups_x, groups_needed.div_ceil(groups_x));
        let gpu_rays: Vec<GpuRay> = rays
            .iter()
            .map(|r| GpuRay {
                origin: r.origin.into(),
                t_max: r.t_max,
                direction: r.direction.into(),
                pad: 0,
            })
            .collect();
        let buffer = |label, size: u64, usage| {
            gpu.device.create_buffer(&wgpu::BufferDescriptor {
                label: Some(label),
                size,
                usage,
                mapped_at_creation: false,
            })
        };
        let storage = wgpu::BufferUsages::STORAGE
            | wgpu::BufferUsages::COPY_DST
            | wgpu::BufferUsages::COPY_SRC;
        let ray_buffer = buffer("rays", n * 32, storage);
        gpu.queue.write_buffer(&ray_buffer, 0, bytemuck::cast_slice(&gpu_rays));
        let hits = buffer("hits", n * 32, storage);
        let points = buffer("surface points", n * size_of::<GpuPoint>() as u64, storage);
        let params = buffer(
            "ray batch params",
            16,
            wgpu::BufferUsages::STORAGE | wgpu::BufferUsages::COPY_DST,
        );
        let p = BatchParams { count, row_pitch: groups_x * WORKGROUP_SIZE, pad: [0; 2] };
        gpu.queue.write_buffer(&params, 0, bytemuck::bytes_of(&p));
        let bind_group = gpu.device.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some("ray batch"),
            layout: &self.layout,
            entries: &[&ray_buffer, &hits, &points, &params]
                .iter()
                .enumerate()
                .map(|(i, b)| wgpu::BindGroupEntry {
                    binding: i as u32,
                    resource: b.as_entire_binding(),
                })
                .collect::<Vec<_>>(),
        });
        Ok(RayBuffers { count, groups, hits, points, bind_group })
    }

    /// Runs one kernel over all rays and waits for the GPU to finish.
    pub fn dispatch(
        &self,
        gpu: &Gpu,
        geometry: &impl BatchGeometry,
        buffers: &RayBuffers,
        kind: TraceKind,
    ) -> Result<(), BvhError> {
        if geometry.stack_entries() > self.stack {
            return Err(BvhError::StackTooSmall {
                compiled: self.stack,
                needed: geometry.stack_entries(),
            });
        }
        let pipeline = match kind {
            TraceKind::Closest => &self.closest,
            TraceKind::Any => &self.any,
            TraceKind::SurfacePoints => &self.points,
        };
        let mut encoder = gpu
            .device
            .create_command_encoder(&wgpu::CommandEncoderDescriptor { label: Some("ray batch") });
        {
            let mut pass = encoder.begin_compute_pass(&wgpu::ComputePassDescriptor {
                label: Some("ray batch"),
                timestamp_writes: None,
            });
            pass.set_pipeline(pipeline);
            pass.set_bind_group(0, &buffers.bind_group, &[]);
            for (i, group) in geometry.bind_groups().into_iter().enumerate() {
                pass.set_bind_group(1 + i as u32, group, &[]);
            }
            pass.dispatch_workgroups(buffers.groups.0, buffers.groups.1, 1);
        }
        let submission = gpu.queue.submit([encoder.finish()]);
        gpu.device
            .poll(wgpu::PollType::Wait { submission_index: Some(submission), timeout: None })
            .map_err(|e| BvhError::Readback { what: "ray batch".into(), reason: e.to_string() })?;
        Ok(())
    }

    /// Closest hits of the last `Closest` dispatch.
    pub fn read_closest(&self, gpu: &Gpu, buffers: &RayBuffers) -> Result<Vec<Hit>, BvhError> {
        let hits: Vec<GpuHit> = read(gpu, &buffers.hits, buffers.count as u64 * 32, "hits")?;
        Ok(hits
            .iter()
            .map(|h| Hit {
                t: h.t,
                instance: h.instance,
                primitive: h.primitive,
                barycentrics: Vec2::from(h.barycentrics),
            })
            .collect())
    }

    /// Any-hit flags of the last `Any` dispatch.
    pub fn read_any(&self, gpu: &Gpu, buffers: &RayBuffers) -> Result<Vec<bool>, BvhError> {
        let hits: Vec<GpuHit> =
            read(gpu, &buffers.hits, buffers.count as u64 * 32, "any-hit flags")?;
        Ok(hits.iter().map(|h| h.any_hit != 0).collect())
    }

    /// Surface records of the last `SurfacePoints` dispatch (meaningless for missed rays).
    pub fn read_surface_points(
        &self,
        gpu: &Gpu,
        buffers: &RayBuffers,
    ) -> Result<Vec<SurfaceRecord>, BvhError> {
        let points: Vec<GpuPoint> = read(
            gpu,
            &buffers.points,
            buffers.count as u64 * size_of::<GpuPoint>() as u64,
            "surface points",
        )?;
        let v3 = |v: [f32; 4]| Vec3::new(v[0], v[1], v[2]);
        Ok(points
            .iter()
            .map(|p| SurfaceRecord {
                position: v3(p.position),
                geometric_normal: v3(p.geometric_normal),
                shading_normal: v3(p.shading_normal),
                uv: Vec2::from(p.uv),
                material: p.material,
                previous_position: v3(p.previous_position),
                triangle: p.triangle.map(v3),
            })
            .collect())
    }

    /// Convenience: closest hits of `rays`.
    pub fn trace_closest(
        &self,
        gpu: &Gpu,
        geometry: &impl BatchGeometry,
        rays: &[RayQuery],
    ) -> Result<Vec<Hit>, BvhError> {
        let buffers = self.upload(gpu, rays)?;
        self.dispatch(gpu, geometry, &buffers, TraceKind::Closest)?;
        self.read_closest(gpu, &buffers)
    }

    /// Convenience: any-hit flags of `rays`.
    pub fn trace_any(
        &self,
        gpu: &Gpu,
        geometry: &impl BatchGeometry,
        rays: &[RayQuery],
    ) -> Result<Vec<bool>, BvhError> {
        let buffers = self.upload(gpu, rays)?;
        self.dispatch(gpu, geometry, &buffers, TraceKind::Any)?;
        self.read_any(gpu, &buffers)
    }
}

/// Copies `size` bytes of `buffer` to a mappable buffer and reads them as `T`s.
fn read<T: bytemuck::Pod>(
    gpu: &Gpu,
    buffer: &wgpu::Buffer,
    size: u64,
    what: &str,
) -> Result<Vec<T>, BvhError> {
    if size == 0 {
        return Ok(Vec::new());
    }
    let staging = gpu.device.create_buffer(&wgpu::BufferDescriptor {
        label: Some("ray batch readback"),
        size,
        usage: wgpu::BufferUsages::MAP_READ | wgpu::BufferUsages::COPY_DST,
        mapped_at_creation: false,
    });
    let mut encoder = gpu
        .device
        .create_command_encoder(&wgpu::CommandEncoderDescriptor { label: Some("readback") });
    encoder.copy_buffer_to_buffer(buffer, 0, &staging, 0, size);
    gpu.queue.submit([encoder.finish()]);
    let (tx, rx) = std::sync::mpsc::channel();
    staging.slice(..).map_async(wgpu::MapMode::Read, move |r| {
        let _ = tx.send(r);
    });
    let fail = |reason: String| BvhError::Readback { what: what.into(), reason };
    gpu.device.poll(wgpu::PollType::wait_indefinitely()).map_err(|e| fail(e.to_string()))?;
    rx.recv().map_err(|e| fail(e.to_string()))?.map_err(|e| fail(e.to_string()))?;
    let view = staging.slice(..).get_mapped_range().map_err(|e| fail(e.to_string()))?;
    let data = bytemuck::cast_slice(&view).to_vec();
    drop(view);
    staging.unmap();
    Ok(data)
}
