//! The scene's geometry on the GPU: both BVH levels, triangles, meshes and instances in one bind
//! group (`@group(1)` of scene_geometry.wgsl). Every table that traversal and hit shading read
//! at a per-ray address is a texel table ([`TexelTable`]: texture fetches, which lavapipe
//! gathers, where it loops over the SIMD lanes for a storage load); only the instance table's
//! header, read at one address by every invocation, is a storage buffer.

use glam::{Mat4, Vec3};
use obvhs::cwbvh::node::CwBvhNode;

use super::cpu_traversal::InstanceUpdate;
use super::tlas::InstanceTransforms;
use super::{BvhError, SceneBvh};
use crate::compute::BufferBinding;
use crate::gpu::Gpu;
use crate::gpu_struct::GpuStruct;
use crate::scene::{Instance, SceneDesc};
use crate::scene_features::SceneFeatures;
use crate::shader::Module;
use crate::texel_table::{TexelTable, whole_rows};

/// Storage buffers the bind group holds (a pass adds its own to the per-stage count).
pub const STORAGE_BUFFERS: u32 = 1;

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
    assert!(
        offset_of!(N, p) == offset_of!(SgNode, origin)
            && offset_of!(N, e) == offset_of!(SgNode, exponents_imask)
            && offset_of!(N, imask) == offset_of!(SgNode, exponents_imask) + 3
    );
    assert!(
        offset_of!(N, child_base_idx) == offset_of!(SgNode, child_base)
            && offset_of!(N, primitive_base_idx) == offset_of!(SgNode, primitive_base)
    );
    assert!(
        offset_of!(N, child_meta) == offset_of!(SgNode, child_meta)
            && offset_of!(N, child_min_x) == offset_of!(SgNode, bounds_x)
    );
    assert!(
        offset_of!(N, child_min_y) == offset_of!(SgNode, bounds_y)
            && offset_of!(N, child_min_z) == offset_of!(SgNode, bounds_z)
    );
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
        /// The TLAS root's record in the node table (the TLAS follows the BLASes there).
        pub tlas_root: u32 => "u32",
        pub pad: u32 => "u32",
    }
}

crate::gpu_struct! {
    /// What traversal needs on entering a TLAS leaf, in TLAS leaf order (so no indirection). Only
    /// instances with triangles are TLAS leaves, so every leaf has a BLAS root node.
    pub struct SgTlasLeaf {
        /// The instance's world box grown by [`LEAF_BOX_PAD`]: traversal enters the instance
        /// only if the ray meets it (scene_geometry.wgsl says why).
        pub box_min: [f32; 3] => "vec3f",
        /// Index into the instance table.
        pub instance: u32 => "u32",
        pub box_max: [f32; 3] => "vec3f",
        /// The instance's BLAS root in the node table.
        pub blas_root: u32 => "u32",
        pub world_to_object: [f32; 16] => "mat4x4f",
    }
}

/// How much a TLAS leaf's world box is grown on each side, relative to its largest coordinate
/// magnitude: 256 times the rounding of the box's corners and of the slab test (2^-24 per
/// operation), and a sixth of what `offset_origin` (pt_scene.wgsl) moves a ray off its surface
/// (1e-4 of the point's magnitude), so that a ray leaving a flat instance misses its box.
pub const LEAF_BOX_PAD: f32 = 1.0 / 65536.0;

/// `b` grown by [`LEAF_BOX_PAD`] of its largest coordinate magnitude on every side.
pub fn padded_leaf_box(b: &obvhs::aabb::Aabb) -> ([f32; 3], [f32; 3]) {
    let (lo, hi) = (Vec3::from(b.min), Vec3::from(b.max));
    let pad = Vec3::splat(lo.abs().max(hi.abs()).max_element() * LEAF_BOX_PAD);
    ((lo - pad).into(), (hi + pad).into())
}

/// The geometry's storage buffer, @group(1) binding 0, declared once (WGSL and layout).
pub const GROUP: [BufferBinding; 1] =
    [BufferBinding::read("sg_instance_header", "SgInstanceHeader")];
const _: () = assert!(crate::compute::storage_buffers(&GROUP) == STORAGE_BUFFERS);

/// The texel tables after the buffer, each record a struct of whole 16-byte texels: (WGSL
/// name, record struct, texels per record).
const TABLES: [(&str, &str, u32); 7] = [
    ("sg_nodes", "SgNode", 5),
    ("sg_triangles", "SgTriangle", 3),
    ("sg_tlas_leaves", "SgTlasLeaf", 6),
    ("sg_instances", "SgInstance", 13),
    ("sg_meshes", "SgMesh", 2),
    ("sg_vertices", "SgVertex", 2),
    ("sg_indices", "vec4u", 1),
];
const NODES: usize = 0;
const TRIANGLES: usize = 1;
const TLAS_LEAVES: usize = 2;
const INSTANCES: usize = 3;
const MESHES: usize = 4;
const VERTICES: usize = 5;
const INDICES: usize = 6;
const fn record_bytes(table: usize) -> usize {
    16 * TABLES[table].2 as usize
}
const _: () = {
    let t = record_bytes;
    assert!(
        size_of::<SgNode>() == t(NODES)
            && size_of::<SgTriangle>() == t(TRIANGLES)
            && size_of::<SgTlasLeaf>() == t(TLAS_LEAVES)
    );
    assert!(
        size_of::<SgInstance>() == t(INSTANCES)
            && size_of::<SgMesh>() == t(MESHES)
            && size_of::<SgVertex>() == t(VERTICES)
            && t(INDICES) == 16
    );
};

const fn texels(table: usize) -> u32 {
    TABLES[table].2
}

pub struct SceneGeometry {
    bvh: SceneBvh,
    layout: wgpu::BindGroupLayout,
    bind_group: wgpu::BindGroup,
    /// The TLAS root's record in the node table (the BLAS nodes come first).
    tlas_root: u32,
    header: wgpu::Buffer,
    /// In [`TABLES`]' order. The node table holds the BLAS nodes from record 0, then the TLAS
    /// from `tlas_root` (a row boundary) with room to grow, as do the TLAS leaves and instances.
    tables: [TexelTable; 7],
}

impl SceneGeometry {
    /// The WGSL interface: its structs (`package::scene_geometry_types`), its @group(1)
    /// (`package::scene_geometry_bindings`) and `package::scene_geometry` (`trace_closest`,
    /// `trace_any`, `surface_point`, ...); a pass that imports them binds [`Self::bind_group`] at
    /// group 1. They start with [`SceneFeatures::ALL`]'s module, which sizes the traversal stack
    /// for any scene; a pass replaces it with its scene's (`Program::replacing`).
    pub fn modules() -> Vec<Module> {
        let types = Self::types();
        let names: Vec<&str> = TABLES.iter().map(|t| t.0).collect();
        let bindings = crate::texel_table::group_module(
            "package::scene_geometry_bindings",
            1,
            &GROUP,
            &names,
            &[&types],
        );
        vec![
            SceneFeatures::ALL.module(),
            crate::texel_table::module(),
            types,
            bindings,
            crate::wgsl_file!("scene_geometry.wgsl"),
        ]
    }

    /// `package::scene_geometry_types`: the structs of the bind group.
    pub fn types() -> Module {
        Module::generated(
            "package::scene_geometry_types",
            &[
                SgNode::WGSL,
                SgTriangle::WGSL,
                SgTlasLeaf::WGSL,
                SgMesh::WGSL,
                SgVertex::WGSL,
                SgInstance::WGSL,
                SgInstanceHeader::WGSL,
            ],
        )
    }

    /// Entries the traversal stack can need in this scene ([`SceneBvh::stack_entries`]); a pass
    /// compiles its stack for it ([`SceneFeatures::traversal_stack`]).
    pub fn stack_entries(&self) -> u32 {
        self.bvh.stack_entries()
    }

    /// Storage buffers in the bind group: a pass adds its own to check the per-stage limit.
    pub const STORAGE_BUFFERS: u32 = STORAGE_BUFFERS;

    /// Texel tables (read-only storage textures) in the bind group.
    pub const TEXEL_TABLES: u32 = TABLES.len() as u32;

    /// Builds every BLAS and the TLAS and uploads them.
    pub fn new(gpu: &Gpu, scene: &SceneDesc) -> Result<Self, BvhError> {
        let limit = gpu.limits.max_storage_buffers_per_shader_stage;
        if limit < STORAGE_BUFFERS {
            return Err(BvhError::StorageBuffers { needed: STORAGE_BUFFERS, limit });
        }
        let bvh = SceneBvh::new(scene)?;

        let nodes = blas_nodes(&bvh);
        let blas_roots = blas_roots(&bvh);
        let mut triangles = Vec::new();
        let mut meshes = Vec::new();
        let mut vertices = Vec::new();
        let mut indices = Vec::new();
        for ((mesh, blas), &node_offset) in scene.meshes.iter().zip(&bvh.blas).zip(&blas_roots) {
            let triangle_offset = triangles.len() as u32;
            triangles.extend(sg_triangles(&blas.triangles, &blas.bvh.primitive_indices));
            let flags = if mesh.normals.is_empty() { 0 } else { HAS_NORMALS }
                | if mesh.uvs.is_empty() { 0 } else { HAS_UVS };
            meshes.push(SgMesh {
                node_offset,
                node_count: blas.bvh.nodes.len() as u32,
                triangle_offset,
                triangle_count: blas.triangles.len() as u32,
                vertex_offset: vertices.len() as u32,
                index_offset: indices.len() as u32,
                flags,
                pad: 0,
            });
            vertices.extend(mesh.positions.iter().enumerate().map(|(i, p)| {
                let n = mesh.normals.get(i).copied().unwrap_or(Vec3::ZERO);
                let uv = mesh.uvs.get(i).copied().unwrap_or_default();
                SgVertex { position: (*p).into(), u: uv.x, normal: n.into(), v: uv.y }
            }));
            indices.extend(mesh.indices.iter().map(|t| [t[0], t[1], t[2], 0]));
        }

        let triangles = TexelTable::new(
            gpu,
            "BLAS triangles",
            texels(TRIANGLES),
            bytemuck::cast_slice(&triangles),
            0,
        )?;
        let meshes =
            TexelTable::new(gpu, "mesh table", texels(MESHES), bytemuck::cast_slice(&meshes), 0)?;
        let vertices =
            TexelTable::new(gpu, "vertices", texels(VERTICES), bytemuck::cast_slice(&vertices), 0)?;
        let indices = TexelTable::new(
            gpu,
            "triangle indices",
            texels(INDICES),
            bytemuck::cast_slice(&indices),
            0,
        )?;
        let tlas_root = whole_rows(nodes.len() as u32);
        let [node_table, tlas_leaves, instances] =
            Self::instance_tables(gpu, &bvh, &nodes, tlas_root)?;
        let header =
            storage_buffer(gpu, "instance table header", &instance_header(&bvh, tlas_root), 0)?;

        let layout = crate::texel_table::group_layout(gpu, "scene geometry", &GROUP, TABLES.len());
        let tables = [node_table, triangles, tlas_leaves, instances, meshes, vertices, indices];
        let bind_group = bind_group(gpu, &layout, &header, &tables);
        Ok(Self { bvh, layout, bind_group, tlas_root, header, tables })
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
    pub fn try_update_instances(
        &mut self,
        gpu: &Gpu,
        instances: &[Instance],
    ) -> Result<InstanceUpdate, BvhError> {
        let update = self.bvh.update_instances(instances)?;
        match update {
            InstanceUpdate::Unchanged => {}
            InstanceUpdate::TableOnly => {
                self.tables[INSTANCES].write(gpu, 0, &instance_records(&self.bvh));
                self.tables[TLAS_LEAVES].write(gpu, 0, &tlas_leaves(&self.bvh));
            }
            InstanceUpdate::Rebuilt => {
                let instances = self.bvh.instances.len() as u32;
                let fits = self.tlas_root + self.bvh.tlas.bvh.nodes.len() as u32
                    <= self.tables[NODES].capacity()
                    && self.bvh.tlas.bvh.primitive_indices.len() as u32
                        <= self.tables[TLAS_LEAVES].capacity()
                    && instances <= self.tables[INSTANCES].capacity();
                if fits {
                    self.tables[NODES].write(
                        gpu,
                        self.tlas_root,
                        &tlas_nodes(&self.bvh, self.tlas_root),
                    );
                    self.tables[TLAS_LEAVES].write(gpu, 0, &tlas_leaves(&self.bvh));
                    self.tables[INSTANCES].write(gpu, 0, &instance_records(&self.bvh));
                } else {
                    // More instances than the tables hold: new ones, so a new bind group
                    // (passes must fetch `bind_group()` each frame).
                    let [n, l, i] = Self::instance_tables(
                        gpu,
                        &self.bvh,
                        &blas_nodes(&self.bvh),
                        self.tlas_root,
                    )?;
                    (self.tables[NODES], self.tables[TLAS_LEAVES], self.tables[INSTANCES]) =
                        (n, l, i);
                    self.bind_group = bind_group(gpu, &self.layout, &self.header, &self.tables);
                }
                gpu.queue.write_buffer(
                    &self.header,
                    0,
                    &instance_header(&self.bvh, self.tlas_root),
                );
            }
        }
        Ok(update)
    }

    /// The node table (the BLAS nodes, then the TLAS from `tlas_root`), the TLAS leaves and the
    /// instance records, with room for twice the current instances so that a growing scene does
    /// not reallocate every frame.
    fn instance_tables(
        gpu: &Gpu,
        bvh: &SceneBvh,
        blas: &[CwBvhNode],
        tlas_root: u32,
    ) -> Result<[TexelTable; 3], BvhError> {
        let room = 2 * bvh.instances.len().max(1) as u64;
        // A CWBVH over n boxes has at most n nodes (every inner node has two or more children).
        let mut nodes = bytemuck::cast_slice(blas).to_vec();
        nodes.resize(tlas_root as usize * size_of::<SgNode>(), 0);
        nodes.extend(tlas_nodes(bvh, tlas_root));
        let nodes =
            TexelTable::new(gpu, "BVH nodes", texels(NODES), &nodes, tlas_root + room as u32)?;
        let leaves = TexelTable::new(
            gpu,
            "TLAS leaves",
            texels(TLAS_LEAVES),
            &tlas_leaves(bvh),
            room as u32,
        )?;
        let instances = TexelTable::new(
            gpu,
            "instance table",
            texels(INSTANCES),
            &instance_records(bvh),
            room as u32,
        )?;
        Ok([nodes, leaves, instances])
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

/// Each BLAS's root in the node table (the BLASes' nodes one after another from record 0).
fn blas_roots(bvh: &SceneBvh) -> Vec<u32> {
    bvh.blas
        .iter()
        .scan(0u32, |next, blas| {
            let root = *next;
            *next += blas.bvh.nodes.len() as u32;
            Some(root)
        })
        .collect()
}

/// Every BLAS's nodes, concatenated, with child and primitive indices made absolute (into the
/// node table and the triangle table).
fn blas_nodes(bvh: &SceneBvh) -> Vec<CwBvhNode> {
    let mut nodes = Vec::new();
    let mut triangle_offset = 0u32;
    for (blas, node_offset) in bvh.blas.iter().zip(blas_roots(bvh)) {
        nodes.extend(blas.bvh.nodes.iter().map(|n| {
            let mut n = *n;
            n.child_base_idx = n.child_base_idx.wrapping_add(node_offset);
            n.primitive_base_idx = n.primitive_base_idx.wrapping_add(triangle_offset);
            n
        }));
        triangle_offset += blas.triangles.len() as u32;
    }
    nodes
}

/// The TLAS nodes as they sit in the node table from record `tlas_root` (child indices made
/// absolute there; primitive indices stay TLAS leaf slots).
fn tlas_nodes(bvh: &SceneBvh, tlas_root: u32) -> Vec<u8> {
    let nodes: Vec<CwBvhNode> = bvh
        .tlas
        .bvh
        .nodes
        .iter()
        .map(|n| {
            let mut n = *n;
            n.child_base_idx = n.child_base_idx.wrapping_add(tlas_root);
            n
        })
        .collect();
    bytemuck::cast_slice(&nodes).to_vec()
}

/// The bind group: the header, then the texel tables in [`TABLES`]' order.
fn bind_group(
    gpu: &Gpu,
    layout: &wgpu::BindGroupLayout,
    header: &wgpu::Buffer,
    tables: &[TexelTable; 7],
) -> wgpu::BindGroup {
    crate::texel_table::group(gpu, "scene geometry", layout, &[header], &tables.each_ref())
}

/// The TLAS leaves in leaf order: each slot's instance, its padded world box, its
/// world-to-object transform and its BLAS root.
fn tlas_leaves(bvh: &SceneBvh) -> Vec<u8> {
    let blas_roots = blas_roots(bvh);
    let leaves: Vec<SgTlasLeaf> = bvh
        .tlas
        .bvh
        .primitive_indices
        .iter()
        .map(|&instance| {
            let i = &bvh.instances[instance as usize];
            let (box_min, box_max) = padded_leaf_box(&super::world_bounds(
                &i.object_to_world,
                &bvh.blas[i.mesh as usize].bounds,
            ));
            SgTlasLeaf {
                box_min,
                instance,
                box_max,
                blas_root: blas_roots[i.mesh as usize],
                world_to_object: i.world_to_object.to_cols_array(),
            }
        })
        .collect();
    bytemuck::cast_slice(&leaves).to_vec()
}

fn instance_header(bvh: &SceneBvh, tlas_root: u32) -> Vec<u8> {
    let header = SgInstanceHeader {
        count: bvh.instances.len() as u32,
        tlas_node_count: bvh.tlas.bvh.nodes.len() as u32,
        tlas_root,
        pad: 0,
    };
    bytemuck::bytes_of(&header).to_vec()
}

fn instance_records(bvh: &SceneBvh) -> Vec<u8> {
    let mut bytes = Vec::new();
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
pub fn sg_triangles<'a>(
    triangles: &'a [[Vec3; 3]],
    primitive_indices: &'a [u32],
) -> impl Iterator<Item = SgTriangle> + 'a {
    triangles.iter().zip(primitive_indices).map(|(t, &p)| SgTriangle {
        v0: t[0].into(),
        primitive: p,
        v1: t[1].into(),
        pad1: 0,
        v2: t[2].into(),
        pad2: 0,
    })
}

/// A read-only storage buffer holding `data`, at least `min_size` bytes (bindings cannot be empty).
pub fn storage_buffer(
    gpu: &Gpu,
    what: &str,
    data: &[u8],
    min_size: u64,
) -> Result<wgpu::Buffer, BvhError> {
    let size = (data.len() as u64).max(min_size).next_multiple_of(16);
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
