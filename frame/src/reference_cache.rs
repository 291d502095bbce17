//! Path-traced references cached on disk under a hash of everything that affects the image:
//! the scene as rendered at that frame, resolution, spp, seed, max depth, adapter and shader
//! sources. A changed shader or scene can never pick up a stale reference.

use std::path::{Path, PathBuf};

use anyhow::Result;
use render::scene::SceneDesc;
use sha2::{Digest, Sha256};

use crate::output;

pub struct ReferenceCache {
    dir: PathBuf,
}

/// What a reference image depends on besides the scene.
pub struct ReferenceKey<'a> {
    pub width: u32,
    pub height: u32,
    pub spp: u32,
    pub seed: u64,
    pub max_depth: u32,
    pub rr_start_depth: u32,
    pub adapter: &'a str,
    pub shader_source: &'a str,
}

impl ReferenceCache {
    pub fn new(dir: impl Into<PathBuf>) -> Self {
        Self { dir: dir.into() }
    }

    /// The cache's folder.
    pub fn dir(&self) -> &Path {
        &self.dir
    }

    /// `$FLICKER_CACHE_DIR`, else `$XDG_CACHE_HOME/flicker`, else `~/.cache/flicker`.
    pub fn default_location() -> PathBuf {
        if let Some(dir) = std::env::var_os("FLICKER_CACHE_DIR") {
            return PathBuf::from(dir);
        }
        let base = std::env::var_os("XDG_CACHE_HOME")
            .map(PathBuf::from)
            .or_else(|| std::env::var_os("HOME").map(|h| Path::new(&h).join(".cache")))
            .unwrap_or_else(std::env::temp_dir);
        base.join("flicker")
    }

    pub fn key(scene: &SceneDesc, key: &ReferenceKey) -> String {
        let mut h = Sha256::new();
        h.update(b"flicker-reference-v1");
        h.update(format!(
            "{}x{} spp{} seed{} depth{} rr{}",
            key.width, key.height, key.spp, key.seed, key.max_depth, key.rr_start_depth
        ));
        h.update(key.adapter.as_bytes());
        h.update(key.shader_source.as_bytes());
        hash_scene(&mut h, scene);
        h.finalize().iter().map(|b| format!("{b:02x}")).collect()
    }

    fn path(&self, key: &str) -> PathBuf {
        self.dir.join("references").join(format!("{key}.exr"))
    }

    pub fn load(&self, key: &str, width: u32, height: u32) -> Option<Vec<[f32; 4]>> {
        let (w, h, px) = output::read_exr(&self.path(key)).ok()?;
        (w == width && h == height).then_some(px)
    }

    pub fn store(&self, key: &str, width: u32, height: u32, pixels: &[[f32; 4]]) -> Result<()> {
        output::write_exr(&self.path(key), width, height, pixels)
    }
}

/// Feeds every field of the scene to the hasher. Floats go in by their bits (or their exact
/// `Debug` form for small structs), so equal scenes hash equal and any change shows.
fn hash_scene(h: &mut Sha256, scene: &SceneDesc) {
    for mesh in &scene.meshes {
        h.update(mesh.name.as_bytes());
        h.update(bytemuck::cast_slice::<_, u8>(&mesh.positions));
        h.update(bytemuck::cast_slice::<_, u8>(&mesh.normals));
        h.update(bytemuck::cast_slice::<_, u8>(&mesh.uvs));
        h.update(bytemuck::cast_slice::<_, u8>(&mesh.indices));
    }
    for tex in &scene.textures {
        h.update(format!("{}x{}", tex.width, tex.height));
        h.update(&tex.rgba8);
    }
    for inst in &scene.instances {
        h.update(format!("{} {}", inst.mesh, inst.material));
        h.update(bytemuck::cast_slice::<_, u8>(&inst.transform.to_cols_array()));
    }
    h.update(format!(
        "{:?}|{:?}|{:?}|{:?}",
        scene.materials, scene.lights, scene.environment, scene.camera
    ));
}

#[cfg(test)]
mod tests {
    use super::*;
    use render::scene::{Instance, Mesh};

    fn key(scene: &SceneDesc, spp: u32) -> String {
        ReferenceCache::key(
            scene,
            &ReferenceKey {
                width: 8,
                height: 4,
                spp,
                seed: 1,
                max_depth: 4,
                rr_start_depth: 3,
                adapter: "a",
                shader_source: "s",
            },
        )
    }

    #[test]
    fn key_changes_with_what_affects_the_image() {
        let mut scene = SceneDesc::default();
        scene.meshes.push(Mesh {
            positions: vec![glam::Vec3::ZERO; 3],
            indices: vec![[0, 1, 2]],
            ..Default::default()
        });
        scene.instances.push(Instance { mesh: 0, material: 0, transform: glam::Mat4::IDENTITY });
        let base = key(&scene, 16);
        assert_eq!(base, key(&scene.clone(), 16));
        assert_ne!(base, key(&scene, 32));
        let mut moved = scene.clone();
        moved.instances[0].transform = glam::Mat4::from_translation(glam::Vec3::X * 1e-3);
        assert_ne!(base, key(&moved, 16));
        let mut lit = scene.clone();
        lit.environment = glam::Vec3::ONE;
        assert_ne!(base, key(&lit, 16));
    }

    #[test]
    fn stores_and_loads() {
        let dir = std::env::temp_dir().join(format!("flicker-refcache-{}", std::process::id()));
        let cache = ReferenceCache::new(&dir);
        let px = vec![[1.0, 2.0, 3.0, 1.0]; 8 * 4];
        assert!(cache.load("k", 8, 4).is_none());
        cache.store("k", 8, 4, &px).unwrap();
        assert_eq!(cache.load("k", 8, 4).unwrap(), px);
        assert!(cache.load("k", 4, 8).is_none());
        std::fs::remove_dir_all(&dir).unwrap();
    }
}
