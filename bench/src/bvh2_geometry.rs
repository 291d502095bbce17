//! The BVH2s of [`SceneBvh2`] on the GPU: every node (all BLAS, then the TLAS) in one texel
//! table of 32-byte nodes with plain f32 boxes, the leaf-order triangles in another (texel
//! tables as the CWBVH's, so that the two traversals are compared on the same kind of loads),
//! and the roots, in one bind group (`@group(2)` of bvh2_traversal.wgsl). The traversal reads
//! the instance table and uses the ray set-up and triangle test of [`SceneGeometry`] (`@group(1)`), so a pass binds both.

use render::bvh::{BvhError, NO_HIT, SceneGeometry, sg_triangles, storage_buffer};
use render::compute::BufferBinding;
use render::gpu::Gpu;
use render::gpu_struct::GpuStruct;
use render::scene::SceneDesc;
use render::shader::Module;
use render::texel_table::TexelTable;

use crate::bvh2::SceneBvh2;

render::gpu_struct! {
    /// obvhs's `Bvh2Node` as the traversal reads it: the box, and `first_index` made absolute.
    pub struct SgBvh2Node {
        pub min: [f32; 3] => "vec3f",
        /// Inner node: its first child (the second follows it). BLAS leaf: its first triangle
        /// in the triangle table. TLAS leaf: its instance.
        pub first_index: u32 => "u32",
        pub max: [f32; 3] => "vec3f",
        /// 0 for an inner node, else the leaf's triangles (1 in a TLAS leaf).
        pub prim_count: u32 => "u32",
    }
}

/// The BVH2 @group(2): the roots (`[0]` the TLAS root, `[1 + m]` mesh m's; `NO_HIT` where
/// empty), then the texel tables [`TABLES`].
pub const GROUP: [BufferBinding; 1] = [BufferBinding::read("bvh2_roots", "array<u32>")];
/// Nodes (an `SgBvh2Node`, 2 texels) and triangles (an `SgTriangle`, 3 texels).
const TABLES: [&str; 2] = ["bvh2_node_table", "bvh2_triangle_table"];
const _: () = assert!(size_of::<SgBvh2Node>() == 32);

pub struct Bvh2Geometry {
    bvh: SceneBvh2,
    layout: wgpu::BindGroupLayout,
    bind_group: wgpu::BindGroup,
    _roots: wgpu::Buffer,
    _tables: [TexelTable; 2],
}

impl Bvh2Geometry {
    /// The WGSL: the node struct, the @group(2) bindings and `package::bench::bvh2_traversal`
    /// (`bvh2_trace_closest`, `bvh2_trace_any`), after [`SceneGeometry::modules`].
    pub fn modules() -> Vec<Module> {
        let types = Module::generated("package::bench::bvh2_types", &[SgBvh2Node::WGSL]);
        let bindings = render::texel_table::group_module(
            "package::bench::bvh2_bindings",
            2,
            &GROUP,
            &TABLES,
            &[&types, &SceneGeometry::types()],
        );
        vec![types, bindings, render::wgsl_file!("bvh2_traversal.wgsl")]
    }

    /// Builds the BVH2s of `scene` and uploads them. `geometry` must be the scene's
    /// [`SceneGeometry`] (its instance table is the one traversal reads).
    pub fn new(gpu: &Gpu, scene: &SceneDesc, geometry: &SceneGeometry) -> Result<Self, BvhError> {
        let needed = SceneGeometry::STORAGE_BUFFERS + render::compute::storage_buffers(&GROUP);
        let limit = gpu.limits.max_storage_buffers_per_shader_stage;
        if limit < needed {
            return Err(BvhError::StorageBuffers { needed, limit });
        }
        let bvh = SceneBvh2::new(scene)?;
        assert_eq!(
            bvh.instances,
            geometry.instances(),
            "the BVH2 and the scene geometry must come from the same scene"
        );
        // The traversal marks a TLAS leaf's instance with bit 31 (BVH2_ENTER).
        assert!(bvh.instances.len() < 1 << 31, "{} instances", bvh.instances.len());
        let node = |n: &obvhs::bvh2::node::Bvh2Node, first_index: u32| SgBvh2Node {
            min: n.aabb().min.into(),
            first_index,
            max: n.aabb().max.into(),
            prim_count: n.prim_count,
        };
        let mut nodes = Vec::new();
        let mut triangles = Vec::new();
        let mut roots = vec![NO_HIT];
        for blas in &bvh.blas {
            let (node_offset, triangle_offset) = (nodes.len() as u32, triangles.len() as u32);
            roots.push(if blas.bvh.nodes.is_empty() { NO_HIT } else { node_offset });
            nodes.extend(blas.bvh.nodes.iter().map(|n| {
                node(n, n.first_index + if n.is_leaf() { triangle_offset } else { node_offset })
            }));
            triangles.extend(sg_triangles(&blas.triangles, &blas.bvh.primitive_indices));
        }
        if !bvh.tlas.nodes.is_empty() {
            let node_offset = nodes.len() as u32;
            roots[0] = node_offset;
            let tlas = &bvh.tlas;
            nodes.extend(tlas.nodes.iter().map(|n| {
                node(
                    n,
                    if n.is_leaf() {
                        tlas.primitive_indices[n.first_index as usize]
                    } else {
                        n.first_index + node_offset
                    },
                )
            }));
        }
        let roots = storage_buffer(gpu, "BVH2 roots", bytemuck::cast_slice(&roots), 4)?;
        let tables = [
            TexelTable::new(gpu, "BVH2 nodes", 2, bytemuck::cast_slice(&nodes), 0)?,
            TexelTable::new(gpu, "BVH2 triangles", 3, bytemuck::cast_slice(&triangles), 0)?,
        ];
        let layout = render::texel_table::group_layout(gpu, "BVH2 geometry", &GROUP, TABLES.len());
        let bind_group = render::texel_table::group(
            gpu,
            "BVH2 geometry",
            &layout,
            &[&roots],
            &tables.each_ref(),
        );
        Ok(Self { bvh, layout, bind_group, _roots: roots, _tables: tables })
    }

    pub fn bind_group_layout(&self) -> &wgpu::BindGroupLayout {
        &self.layout
    }

    pub fn bind_group(&self) -> &wgpu::BindGroup {
        &self.bind_group
    }

    /// The same BVH2s on the CPU (reference traversal).
    pub fn cpu(&self) -> &SceneBvh2 {
        &self.bvh
    }
}
