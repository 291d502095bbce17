//! Materials and base-colour textures in the layout of path_tracer.wgsl: one `GpuMaterial` per
//! scene material and every texture's RGBA8 texels (still sRGB-encoded) in one atlas buffer.

use crate::error::RenderError;
use crate::scene::SceneDesc;
use bytemuck::Zeroable;

pub(crate) const NO_TEXTURE: u32 = u32::MAX;

crate::gpu_struct! {
    /// One scene material as the shaders read it (texel table `material_table`, @group(0)
    /// binding 2, read with `material(i)`).
    pub struct GpuMaterial {
        pub base_color: [f32; 3] => "vec3f",
        /// First texel in `texels`, NO_TEXTURE if none.
        pub texture_offset: u32 => "u32",
        pub emission: [f32; 3] => "vec3f",
        pub roughness: f32 => "f32",
        pub metallic: f32 => "f32",
        pub specular: f32 => "f32",
        pub texture_width: u32 => "u32",
        pub texture_height: u32 => "u32",
    }
}

const _: () = assert!(size_of::<GpuMaterial>() == 48);

/// Packs the materials and the texture atlas; refuses dangling texture indices and texel
/// arrays that do not match their size.
pub(crate) fn pack_materials(
    scene: &SceneDesc,
) -> Result<(Vec<GpuMaterial>, Vec<u32>), RenderError> {
    let mut offsets = Vec::with_capacity(scene.textures.len());
    let mut texels: Vec<u32> = Vec::new();
    for (i, t) in scene.textures.iter().enumerate() {
        let expected = t.width as usize * t.height as usize * 4;
        if t.rgba8.len() != expected || expected == 0 {
            return Err(RenderError::Scene(format!(
                "texture {i} '{}' is {}x{} so needs {expected} RGBA8 bytes, but has {}",
                t.name,
                t.width,
                t.height,
                t.rgba8.len()
            )));
        }
        offsets.push(texels.len() as u32);
        texels
            .extend(t.rgba8.chunks_exact(4).map(|c| u32::from_le_bytes([c[0], c[1], c[2], c[3]])));
    }
    if texels.is_empty() {
        texels.push(0); // storage buffers may not be empty
    }
    let mut materials = Vec::with_capacity(scene.materials.len().max(1));
    for (i, m) in scene.materials.iter().enumerate() {
        let (texture_offset, texture_width, texture_height) = match m.base_color_texture {
            None => (NO_TEXTURE, 0, 0),
            Some(t) => {
                let tex = scene.textures.get(t as usize).ok_or_else(|| {
                    RenderError::Scene(format!(
                        "material {i} uses base-colour texture {t}, but the scene has {} textures",
                        scene.textures.len()
                    ))
                })?;
                (offsets[t as usize], tex.width, tex.height)
            }
        };
        materials.push(GpuMaterial {
            base_color: m.base_color.to_array(),
            texture_offset,
            emission: m.emission.to_array(),
            roughness: m.roughness,
            metallic: m.metallic,
            specular: m.specular,
            texture_width,
            texture_height,
        });
    }
    for (i, inst) in scene.instances.iter().enumerate() {
        if inst.material as usize >= scene.materials.len() {
            return Err(RenderError::Scene(format!(
                "instance {i} uses material {}, but the scene has {} materials",
                inst.material,
                scene.materials.len()
            )));
        }
    }
    if materials.is_empty() {
        materials.push(GpuMaterial::zeroed());
    }
    Ok((materials, texels))
}
