//! The scene's @group(0) as every pass of the library declares it: a method's frame parameters,
//! the base-colour texels and the texel tables of materials and lights. `SceneGpu` binds it,
//! `PassLibrary` generates its WGSL declarations and counts it against the adapter's limits.

use crate::compute::{self, BufferBinding};

/// @group(0)'s buffers: frame parameters, texels (declared into the library's WGSL).
pub const GROUP: [BufferBinding; 2] =
    [BufferBinding::read("frame", "Frame"), BufferBinding::read("texels", "array<u32>")];
/// Its texel tables after the buffers: `GpuMaterial`s (3 texels) and `GpuLight`s (4 texels),
/// read through scene_tables.wgsl.
pub const TABLES: [&str; 2] = ["material_table", "light_table"];
pub(crate) const MATERIAL_TEXELS: u32 = 3;
pub(crate) const LIGHT_TEXELS: u32 = 4;
const _: () = assert!(size_of::<crate::materials::GpuMaterial>() == 16 * MATERIAL_TEXELS as usize);
const _: () = assert!(size_of::<crate::lights::GpuLight>() == 16 * LIGHT_TEXELS as usize);

/// Storage buffers of @group(0).
pub const STORAGE_BUFFERS: u32 = compute::storage_buffers(&GROUP);
