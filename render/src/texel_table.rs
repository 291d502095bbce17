//! Fixed-size records in an `rgba32uint` texture, bound as a read-only storage texture and read
//! in WGSL with `textureLoad`.
//!
//! Why a texture and not a storage buffer: on Mesa 22.3's lavapipe (what CI runs) a storage load
//! at a per-invocation address is a loop over the 8 SIMD lanes for every 32-bit word, while a
//! texel load is gathered. Why a read-only storage texture and not a sampled one: lavapipe
//! fetches a sampled texel through an out-of-line function that looks up every lane's mip level,
//! and reads a storage texel inline. `cargo run -p bench --example load_probe` measures chains of
//! dependent 16-byte loads all three ways (docs/lab/render-speed.md). BVH nodes and triangles are
//! read-only during a frame and fetched at data-dependent addresses on every traversal step,
//! which is the case this helps; on GPUs a texel load is as fast as a buffer load
//! (texture-bound BVHs are the classic layout, Aila & Laine 2009).
//!
//! Layout: record `i` is texels `(TEXELS * (i % RECORDS_PER_ROW) + j, i / RECORDS_PER_ROW)`,
//! `j < TEXELS`, so a record never spans two rows and a row-aligned range can be rewritten alone.

use crate::compute::BufferBinding;
use crate::gpu::{Gpu, GpuError};
use crate::shader::Module;

/// Records per texture row (a power of two: the shader splits an index with a shift and a mask).
pub const RECORDS_PER_ROW_LOG2: u32 = 9;
pub const RECORDS_PER_ROW: u32 = 1 << RECORDS_PER_ROW_LOG2;
const TEXEL_BYTES: usize = 16;

pub struct TexelTable {
    what: String,
    texture: wgpu::Texture,
    view: wgpu::TextureView,
    /// 16-byte texels per record.
    texels: u32,
    /// Records the texture holds.
    capacity: u32,
}

impl TexelTable {
    /// A table of `texels` texels per record, holding at least `capacity` records (at least one
    /// row: bindings cannot be empty), filled with `records` from record 0.
    pub fn new(
        gpu: &Gpu,
        what: &str,
        texels: u32,
        records: &[u8],
        capacity: u32,
    ) -> Result<Self, GpuError> {
        let record_bytes = texels as usize * TEXEL_BYTES;
        assert!(
            records.len().is_multiple_of(record_bytes),
            "{what}: {} bytes is not a whole number of {record_bytes}-byte records",
            records.len()
        );
        let count = (records.len() / record_bytes) as u32;
        let rows = count.max(capacity).max(1).div_ceil(RECORDS_PER_ROW);
        let width = texels * RECORDS_PER_ROW;
        let max = gpu.limits.max_texture_dimension_2d;
        if width > max {
            return Err(GpuError::OverLimit {
                what: format!("{what} texture width"),
                requested: width as u64,
                limit: max as u64,
                adapter: gpu.summary.to_string(),
            });
        }
        if rows > max {
            return Err(GpuError::OverLimit {
                what: format!("{what}: texture rows of {RECORDS_PER_ROW} records"),
                requested: rows as u64,
                limit: max as u64,
                adapter: gpu.summary.to_string(),
            });
        }
        let texture = gpu.device.create_texture(&wgpu::TextureDescriptor {
            label: Some(what),
            size: wgpu::Extent3d { width, height: rows, depth_or_array_layers: 1 },
            mip_level_count: 1,
            sample_count: 1,
            dimension: wgpu::TextureDimension::D2,
            format: wgpu::TextureFormat::Rgba32Uint,
            usage: wgpu::TextureUsages::STORAGE_BINDING | wgpu::TextureUsages::COPY_DST,
            view_formats: &[],
        });
        let view = texture.create_view(&wgpu::TextureViewDescriptor::default());
        let table = Self {
            what: what.to_string(),
            texture,
            view,
            texels,
            capacity: rows * RECORDS_PER_ROW,
        };
        table.write(gpu, 0, records);
        Ok(table)
    }

    /// Writes `records` from record `first`, a multiple of [`RECORDS_PER_ROW`]; the rest of the
    /// last row written is zeroed. Panics if they do not fit (callers check [`Self::capacity`]).
    pub fn write(&self, gpu: &Gpu, first: u32, records: &[u8]) {
        assert!(first.is_multiple_of(RECORDS_PER_ROW), "texel table writes start on a row");
        let row_bytes = self.texels as usize * TEXEL_BYTES * RECORDS_PER_ROW as usize;
        let rows = records.len().div_ceil(row_bytes) as u32;
        if rows == 0 {
            return;
        }
        assert!(
            first + rows * RECORDS_PER_ROW <= self.capacity,
            "texel table write past its capacity"
        );
        let mut padded = records.to_vec();
        padded.resize(rows as usize * row_bytes, 0);
        gpu.queue.write_texture(
            wgpu::TexelCopyTextureInfo {
                texture: &self.texture,
                mip_level: 0,
                origin: wgpu::Origin3d { x: 0, y: first / RECORDS_PER_ROW, z: 0 },
                aspect: wgpu::TextureAspect::All,
            },
            &padded,
            wgpu::TexelCopyBufferLayout {
                offset: 0,
                bytes_per_row: Some(row_bytes as u32),
                rows_per_image: Some(rows),
            },
            wgpu::Extent3d {
                width: self.texels * RECORDS_PER_ROW,
                height: rows,
                depth_or_array_layers: 1,
            },
        );
    }

    /// Replaces the whole table with `records`: written in place if they fit, else into a new
    /// texture of the same kind. True when the texture is new (its bind groups must be rebuilt).
    pub fn replace(&mut self, gpu: &Gpu, records: &[u8]) -> Result<bool, GpuError> {
        let count = records.len() / (self.texels as usize * TEXEL_BYTES);
        if count <= self.capacity as usize {
            self.write(gpu, 0, records);
            return Ok(false);
        }
        *self = Self::new(gpu, &self.what, self.texels, records, 0)?;
        Ok(true)
    }

    /// Records the texture holds.
    pub fn capacity(&self) -> u32 {
        self.capacity
    }

    pub fn view(&self) -> &wgpu::TextureView {
        &self.view
    }

    /// The bind group layout entry of such a table at `binding`, visible to compute.
    pub fn layout_entry(binding: u32) -> wgpu::BindGroupLayoutEntry {
        wgpu::BindGroupLayoutEntry {
            binding,
            visibility: wgpu::ShaderStages::COMPUTE,
            ty: wgpu::BindingType::StorageTexture {
                access: wgpu::StorageTextureAccess::ReadOnly,
                format: wgpu::TextureFormat::Rgba32Uint,
                view_dimension: wgpu::TextureViewDimension::D2,
            },
            count: None,
        }
    }
}

/// Rounds a record count up to whole rows (where a second region of one table may start).
pub fn whole_rows(records: u32) -> u32 {
    records.div_ceil(RECORDS_PER_ROW) * RECORDS_PER_ROW
}

/// `package::texel_table`: `texel_fetch(table, record, texels, j)`, texel `j` of record `record`
/// of a table of `texels` texels per record.
pub fn module() -> Module {
    Module::generated(
        "package::texel_table",
        &[&format!(
            "const RECORDS_PER_ROW_LOG2: u32 = {RECORDS_PER_ROW_LOG2}u;\n\
             fn texel_fetch(table: texture_storage_2d<rgba32uint, read>, record: u32, texels: u32, j: u32) -> vec4u {{\n\
             \x20   let row_mask = (1u << RECORDS_PER_ROW_LOG2) - 1u;\n\
             \x20   return textureLoad(table, vec2u(texels * (record & row_mask) + j, record >> RECORDS_PER_ROW_LOG2));\n\
             }}\n"
        )],
    )
}

// A group of buffers and texel tables: the buffers at bindings 0.., the tables after them. The
// three functions below are its WGSL, its layout and its bind group.

/// [`crate::compute::group_module`] of `buffers`, with the texel tables `tables` declared after them.
pub fn group_module(
    path: &str,
    group: u32,
    buffers: &[BufferBinding],
    tables: &[&str],
    types: &[&Module],
) -> Module {
    let mut module = crate::compute::group_module(path, group, buffers, types);
    let declarations: String = tables
        .iter()
        .enumerate()
        .map(|(i, name)| {
            format!(
                "@group({group}) @binding({}) var {name}: texture_storage_2d<rgba32uint, read>;\n",
                buffers.len() + i
            )
        })
        .collect();
    module.source = format!("{}{declarations}", module.source).into();
    module
}

/// The layout of `buffers`, then `tables` texel tables, visible to compute.
pub fn group_layout(
    gpu: &Gpu,
    label: &str,
    buffers: &[BufferBinding],
    tables: usize,
) -> wgpu::BindGroupLayout {
    let mut entries = crate::compute::buffer_entries(
        &buffers.iter().map(BufferBinding::kind).collect::<Vec<_>>(),
    );
    entries.extend((0..tables).map(|i| TexelTable::layout_entry((buffers.len() + i) as u32)));
    gpu.device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
        label: Some(label),
        entries: &entries,
    })
}

/// The bind group of such a layout: `buffers` whole, then `tables`.
pub fn group(
    gpu: &Gpu,
    label: &str,
    layout: &wgpu::BindGroupLayout,
    buffers: &[&wgpu::Buffer],
    tables: &[&TexelTable],
) -> wgpu::BindGroup {
    let mut entries: Vec<_> = buffers
        .iter()
        .enumerate()
        .map(|(i, b)| wgpu::BindGroupEntry { binding: i as u32, resource: b.as_entire_binding() })
        .collect();
    for (i, table) in tables.iter().enumerate() {
        entries.push(wgpu::BindGroupEntry {
            binding: (buffers.len() + i) as u32,
            resource: wgpu::BindingResource::TextureView(table.view()),
        });
    }
    gpu.device.create_bind_group(&wgpu::BindGroupDescriptor {
        label: Some(label),
        layout,
        entries: &entries,
    })
}
