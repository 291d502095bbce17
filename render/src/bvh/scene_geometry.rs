//! The scene's geometry on the GPU: both BVH levels, triangles and instances in storage buffers
//! of one bind group (`@group(1)` of scene_geometry.wgsl).

use glam::{Mat4, Vec3};

use super::cpu_traversal::InstanceUpdate;
use super::tlas::InstanceTransforms;
use super::{BvhError, SceneBvh};
use crate::compute::BufferBinding;
use crate::gpu::Gpu;
use crate::gpu_struct::GpuStruct;
use crate::shader::Module;
use crate::scene::{Instance, SceneDesc};

/// Storage buffers the bind group holds (a pass adds its own to the per-stage count).
pub const STORAGE_BUFFERS: u32 = 8;

crate::gpu_struct! {
    /// obvhs's `CwBvhNode` as the traversal reads it: the same 80 bytes (uploaded by a cast), its
    /// byte fields read as words.
    pub struct SgNode {
        /// Min corner of the node's child grid (`p`).
        pub origin: [f32; 3] => "vec3f",
        /// Bytes: exponents x, y, z of the grid scale (2^(e-127)), then `imask`.
        pub exponents_imask: u32 => "u32",
        /// First child node (children are contiguous).
        pub child_base: u32 => "u32",
        /// First leaf primitive slot.
        pub primitive_base: u32 => "u32",
        /// One byte per child slot: leaf = count (unary, bits 5-7) | offset; inner = 24 + slot.
        pub child_meta: [u32; 2] => "vec2u",
        /// .xy: quantized child minima (one byte per child), .zw: maxima.
        pub bounds_x: [u32; 4] => "vec4u",
        pub bounds_y: [u32; 4] => "vec4u",
        pub bounds_z: [u32; 4] => "vec4u",
    }
}

// SgNode is CwBvhNode's bytes: same size, and each word where obvhs keeps its field.
const _: () = {
    use obvhs::cwbvh::node::CwBvhNode as N;
    use std::mem::offset_of;
    assert!(size_of::<N>() == size_of::<SgNode>());
    assert!(offset_of!(N, p) == offset_of!(SgNode, origin) && offset_of!(N, e) == offset_of!(SgNode, exponents_imask) && offset_of!(N, imask) == offset_of!(SgNode, exponents_imask) + 3);
    assert!(offset_of!(N, child_base_idx) == offset_of!(SgNode, child_base) && offset_of!(N, primitive_base_idx) == offset_of!(SgNode, primitive_base));
    assert!(offset_of!(N, child_meta) == offset_of!(SgNode, child_meta) && offset_of!(N, child_min_x) == offset_of!(SgNode, bounds_x));
    assert!(offset_of!(N, child_min_y) == offset_of!(SgNode, bounds_y) && offset_of!(N, child_min_z) == offset_of!(SgNode, bounds_z));
};

crate::gpu_struct! {
    /// A BLAS triangle in leaf order, object space.
    pub struct SgTriangle {
        pub v0: [f32; 3] => "vec3f",
        pub primitive: u32 => "u32",
        pub v1: [f32; 3] => "vec3f",
        pub pad1: u32 => "u32",
        pub v2: [f32; 3] => "vec3f",
        pub pad2: u32 => "u32",
    }
}

crate::gpu_struct! {
    pub struct SgMesh {
        /// Root of this mesh's BLAS in sg_blas_nodes.
        pub node_offset: u32 => "u32",
        pub node_count: u32 => "u32",
        /// First slot in sg_blas_triangles.
        pub triangle_offset: u32 => "u32",
        pub triangle_count: u32 => "u32",
        /// First vertex in sg_vertices.
        pub vertex_offset: u32 => "u32",
        /// First triangle in sg_indices (3 indices each).
        pub index_offset: u32 => "u32",
        /// Bit 0: has shading normals, bit 1: has uvs.
        pub flags: u32 => "u32",
        pub pad: u32 => "u32",
    }
}

const HAS_NORMALS: u32 = 1;
const HAS_UVS: u32 = 2;

crate::gpu_struct! {
    pub struct SgVertex {
        pub position: [f32; 3] => "vec3f",
        pub u: f32 => "f32",
        pub normal: [f32; 3] => "vec3f",
        pub v: f32 => "f32",
    }
}

crate::gpu_struct! {
    pub struct SgInstance {
        pub object_to_world: [f32; 16] => "mat4x4f",
        pub world_to_object: [f32; 16] => "mat4x4f",
        pub previous_object_to_world: [f32; 16] => "mat4x4f",
        pub mesh: u32 => "u32",
        pub material: u32 => "u32",
        pub pad: [u32; 2] => "vec2u",
    }
}

crate::gpu_struct! {
    /// The head of the instance table (its records follow at byte 16).
    pub struct SgInstanceHeader {
        pub count: u32 => "u32",
        pub tlas_node_count: u32 => "u32",
        pub pad: [u32; 2] => "vec2u",
    }
}

/// The geometry's @group(1), declared once (its WGSL and its layout).
pub const GROUP: [BufferBinding; 8] = [
    BufferBinding::read("sg_blas_nodes", "array<SgNode>"),
    BufferBinding::read("sg_blas_triangles", "array<SgTriangle>"),
    BufferBinding::read("sg_meshes", "array<SgMesh>"),
    BufferBinding::read("sg_vertices", "array<SgVertex>"),
    BufferBinding::read("sg_indices", "array<u32>"),
    BufferBinding::read("sg_tlas_nodes", "array<SgNode>"),
    BufferBinding::read("sg_tlas_instances", "array<u32>"),
    BufferBinding::read("sg_instances", "SgInstanceTable"),
];
const _: () = assert!(crate::compute::storage_buffers(&GROUP) == STORAGE_BUFFERS);

pub struct SceneGeometry {
    bvh: SceneBvh,
    layout: wgpu::BindGroupLayout,
    bind_group: wgpu::BindGroup,
    blas_nodes: wgpu::Buffer,
    blas_triangles: wgpu::Buffer,
    meshes: wgpu::Buffer,
    vertices: wgpu::Buffer,
    indices: wgpu::Buffer,
    tlas_nodes: wgpu::Buffer,
    tlas_instances: wgpu::Buffer,
    instances: wgpu::Buffer,
}

impl SceneGeometry {
    /// The WGSL interface: its structs (`package::scene_geometry_types`), its @group(1)
    /// (`package::scene_geometry_bindings`) and `package::scene_geometry` (`trace_closest`,
    /// `trace_any`, `surface_point`, ...); a pass that imports them binds [`Self::bind_group`] at
    /// group 1.
    pub fn modules() -> Vec<Module> {
        let types = Self::types();
        let bindings = crate::compute::group_module("package::scene_geometry_bindings", 1, &GROUP, &[&types]);
        vec![types, bindings, crate::wgsl_file!("scene_geometry.wgsl")]
    }

    /// `package::scene_geometry_types`: the structs of the bind group.
    pub(crate) fn types() -> Module {
        Module::generated(
            "package::scene_geometry_types",
            &[SgNode::WGSL, SgTriangle::WGSL, SgMesh::WGSL, SgVertex::WGSL, SgInstance::WGSL, SgInstanceHeader::WGSL, "struct SgInstanceTable { header: SgInstanceHeader, records: array<SgInstance> }\n"],
        )
    }

    /// Storage buffers in the bind group: a pass adds its own to check the per-stage limit.
    pub const STORAGE_BUFFERS: u32 = STORAGE_BUFFERS;

    /// Builds every BLAS and the TLAS and uploads them.
    pub fn new(gpu: &Gpu, scene: &SceneDesc) -> Result<Self, BvhError> {
        let limit = gpu.limits.max_storage_buffers_per_shader_stage;
        if limit < STORAGE_BUFFERS {
            return Err(BvhError::StorageBuffers { needed: STORAGE_BUFFERS, limit });
        }
        let bvh = SceneBvh::new(scene)?;

        let mut nodes = Vec::new();
        let mut triangles = Vec::new();
        let mut meshes = Vec::new();
        let mut vertices = Vec::new();
        let mut indices = Vec::new();
        for (mesh, blas) in scene.meshes.iter().zip(&bvh.blas) {
            let node_offset = nodes.len() as u32;
            let triangle_offset = triangles.len() as u32;
            // Child and primitive indices become absolute in the concatenated buffers.
            nodes.extend(blas.bvh.nodes.iter().map(|n| {
                let mut n = *n;
                n.child_base_idx = n.child_base_idx.wrapping_add(node_offset);
                n.primitive_base_idx = n.primitive_base_idx.wrapping_add(triangle_offset);
                n
            }));
            triangles.extend(sg_triangles(&blas.triangles, &blas.bvh.primitive_indices));
            let flags = if mesh.normals.is_empty() { 0 } else { HAS_NORMALS } | if mesh.uvs.is_empty() { 0 } else { HAS_UVS };
            meshes.push(SgMesh {
                node_offset,
                node_count: blas.bvh.nodes.len() as u32,
                triangle_offset,
                triangle_count: blas.triangles.len() as u32,
                vertex_offset: vertices.len() as u32,
                index_offset: (indices.len() / 3) as u32,
                flags,
                pad: 0,
            });
            vertices.extend(mesh.positions.iter().enumerate().map(|(i, p)| {
                let n = mesh.normals.get(i).copied().unwrap_or(Vec3::ZERO);
                let uv = mesh.uvs.get(i).copied().unwrap_or_default();
                SgVertex { position: (*p).into(), u: uv.x, normal: n.into(), v: uv.y }
            }));
            indices.extend(mesh.indices.iter().flatten().copied());
        }

        let blas_nodes = storage(gpu, "BLAS nodes", bytemuck::cast_slice(&nodes), 80)?;
        let blas_triangles = storage(gpu, "BLAS triangles", bytemuck::cast_slice(&triangles), 48)?;
        let meshes = storage(gpu, "mesh table", bytemuck::cast_slice(&meshes), 32)?;
        let vertices = storage(gpu, "vertices", bytemuck::cast_slice(&vertices), 32)?;
        let indices = storage(gpu, "triangle indices", bytemuck::cast_slice(&indices), 4)?;
        let (tlas_nodes, tlas_instances, instances) = Self::instance_buffers(gpu, &bvh)?;

        let layout = crate::compute::binding_layout(gpu, "scene geometry", &GROUP);
        let bind_group = gpu.device.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some("scene geometry"),
            layout: &layout,
            entries: &[&blas_nodes, &blas_triangles, &meshes, &vertices, &indices, &tlas_nodes, &tlas_instances, &instances]
                .iter()
                .enumerate()
                .map(|(i, b)| wgpu::BindGroupEntry { binding: i as u32, resource: b.as_entire_binding() })
                .collect::<Vec<_>>(),
        });
        Ok(Self { bvh, layout, bind_group, blas_nodes, blas_triangles, meshes, vertices, indices, tlas_nodes, tlas_instances, instances })
    }

    /// Next frame's instances: the current transforms become the previous ones (motion
    /// vectors) and the TLAS is rebuilt if anything moved; nothing is uploaded if nothing
    /// changed. Panics with the reason on an invalid instance (see [`Self::try_update_instances`]).
    pub fn update_instances(&mut self, gpu: &Gpu, instances: &[Instance]) {
        if let Err(e) = self.try_update_instances(gpu, instances) {
            panic!("SceneGeometry::update_instances: {e}");
        }
    }

    /// [`Self::update_instances`], returning what it did or why the instances are invalid.
    pub fn try_update_instances(&mut self, gpu: &Gpu, instances: &[Instance]) -> Result<InstanceUpdate, BvhError> {
        let update = self.bvh.update_instances(instances)?;
        match update {
            InstanceUpdate::Unchanged => {}
            InstanceUpdate::TableOnly => {
                gpu.queue.write_buffer(&self.instances, 0, &instance_table(&self.bvh));
            }
            InstanceUpdate::Rebuilt => {
                let tlas = tlas_nodes(&self.bvh);
                let table = instance_table(&self.bvh);
                let fits = tlas.len() as u64 <= self.tlas_nodes.size()
                    && self.bvh.tlas.bvh.primitive_indices.len() as u64 * 4 <= self.tlas_instances.size()
                    && table.len() as u64 <= self.instances.size();
                if fits {
                    gpu.queue.write_buffer(&self.tlas_nodes, 0, &tlas);
                    gpu.queue.write_buffer(&self.tlas_instances, 0, bytemuck::cast_slice(&self.bvh.tlas.bvh.primitive_indices));
                    gpu.queue.write_buffer(&self.instances, 0, &table);
                } else {
                    // More instances than the buffers hold: new buffers, so a new bind group
                    // (passes must fetch `bind_group()` each frame).
                    let (t, ti, i) = Self::instance_buffers(gpu, &self.bvh)?;
                    (self.tlas_nodes, self.tlas_instances, self.instances) = (t, ti, i);
                    self.bind_group = gpu.device.create_bind_group(&wgpu::BindGroupDescriptor {
                        label: Some("scene geometry"),
                        layout: &self.layout,
                        entries: &[
                            &self.blas_nodes,
                            &self.blas_triangles,
                            &self.meshes,
                            &self.vertices,
                            &self.indices,
                            &self.tlas_nodes,
                            &self.tlas_instances,
                            &self.instances,
                        ]
                        .iter()
                        .enumerate()
                        .map(|(i, b)| wgpu::BindGroupEntry { binding: i as u32, resource: b.as_entire_binding() })
                        .collect::<Vec<_>>(),
                    });
                }
            }
        }
        Ok(update)
    }

    /// TLAS nodes, TLAS leaf -> instance, and the instance table, with room for twice the
    /// current instances so that a growing scene does not reallocate every frame.
    fn instance_buffers(gpu: &Gpu, bvh: &SceneBvh) -> Result<(wgpu::Buffer, wgpu::Buffer, wgpu::Buffer), BvhError> {
        let room = 2 * bvh.instances.len().max(1) as u64;
        // A CWBVH over n boxes has at most n nodes (every inner node has two or more children).
        let tlas = storage_with_capacity(gpu, "TLAS nodes", &tlas_nodes(&bvh), room * 80)?;
        let leaves = storage_with_capacity(gpu, "TLAS instance indices", bytemuck::cast_slice(&bvh.tlas.bvh.primitive_indices), room * 4)?;
        let table = storage_with_capacity(gpu, "instance table", &instance_table(bvh), 16 + room * 208)?;
        Ok((tlas, leaves, table))
    }

    pub fn bind_group_layout(&self) -> &wgpu::BindGroupLayout {
        &self.layout
    }

    /// Changes when the instance buffers had to grow: fetch it every frame.
    pub fn bind_group(&self) -> &wgpu::BindGroup {
        &self.bind_group
    }

    /// World bounds of the scene's instances; (0, 0) for a scene without geometry.
    pub fn bounds(&self) -> (Vec3, Vec3) {
        self.bvh.bounds()
    }

    /// The same BVHs on the CPU (reference traversal, benchmarks).
    pub fn cpu(&self) -> &SceneBvh {
        &self.bvh
    }

    pub fn instances(&self) -> &[InstanceTransforms] {
        &self.bvh.instances
    }
}

fn tlas_nodes(bvh: &SceneBvh) -> Vec<u8> {
    bytemuck::cast_slice(&bvh.tlas.bvh.nodes).to_vec()
}

fn instance_table(bvh: &SceneBvh) -> Vec<u8> {
    let header = SgInstanceHeader { count: bvh.instances.len() as u32, tlas_node_count: bvh.tlas.bvh.nodes.len() as u32, pad: [0; 2] };
    let mut bytes = bytemuck::bytes_of(&header).to_vec();
    let m = |m: &Mat4| m.to_cols_array();
    for i in &bvh.instances {
        let record = SgInstance {
            object_to_world: m(&i.object_to_world),
            world_to_object: m(&i.world_to_object),
            previous_object_to_world: m(&i.previous_object_to_world),
            mesh: i.mesh,
            material: i.material,
            pad: [0; 2],
        };
        bytes.extend_from_slice(bytemuck::bytes_of(&record));
    }
    bytes
}

/// Leaf-order triangles as the GPU reads them, each with its mesh triangle index.
pub(super) fn sg_triangles<'a>(triangles: &'a [[Vec3; 3]], primitive_indices: &'a [u32]) -> impl Iterator<Item = SgTriangle> + 'a {
    triangles.iter().zip(primitive_indices).map(|(t, &p)| SgTriangle { v0: t[0].into(), primitive: p, v1: t[1].into(), pad1: 0, v2: t[2].into(), pad2: 0 })
}

/// A read-only storage buffer holding `data`, at least `min_size` bytes (bindings cannot be empty).
pub(super) fn storage(gpu: &Gpu, what: &str, data: &[u8], min_size: u64) -> Result<wgpu::Buffer, BvhError> {
    storage_with_capacity(gpu, what, data, min_size)
}

fn storage_with_capacity(gpu: &Gpu, what: &str, data: &[u8], capacity: u64) -> Result<wgpu::Buffer, BvhError> {
    let size = (data.len() as u64).max(capacity).next_multiple_of(16);
    gpu.check_buffer_size(what, size)?;
    let buffer = gpu.device.create_buffer(&wgpu::BufferDescriptor {
        label: Some(what),
        size,
        usage: wgpu::BufferUsages::STORAGE | wgpu::BufferUsages::COPY_DST,
        mapped_at_creation: false,
    });
    gpu.queue.write_buffer(&buffer, 0, data);
    Ok(buffer)
}

