//! Path-traced references cached on disk under a hash of everything that affects the image:
//! the scene as rendered at that frame, resolution, spp, seed, max depth, adapter, shader
//! sources and the host code that shapes the image (`host_source::HASH`). A changed shader,
//! host code or scene can never pick up a stale reference.
//!
//! An entry is one file, `references/KEY.ref`, written whole through a rename: a magic tag,
//! width and height, the SHA-256 of the pixels, then the pixels (RGBA f32, little-endian). A
//! truncated or altered entry fails its checksum and is rendered again, never used.
//!
//! Runs and sweep jobs that share a cache render each entry once: whoever misses takes an
//! exclusive advisory lock on `references/KEY.lock` (std's `File::lock`: `flock` on Unix,
//! `LockFileEx` on Windows), looks again, and renders only if the entry is still missing. The
//! OS releases the lock when its holder exits or is killed, so a lock file left behind never
//! blocks anyone; the files stay (removing one would race with a run waiting on it).

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
    /// The host code that shaped it: `host_source::HASH` of the binary that renders it.
    pub host_source: &'a str,
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
        h.update(key.host_source.as_bytes());
        hash_scene(&mut h, scene);
        h.finalize().iter().map(|b| format!("{b:02x}")).collect()
    }

    /// The file of an entry.
    pub fn path(&self, key: &str) -> PathBuf {
        self.dir.join("references").join(format!("{key}.ref"))
    }

    /// The entry of `key`: its pixels, none, or why it cannot be used.
    pub fn lookup(&self, key: &str, width: u32, height: u32) -> Lookup {
        let path = self.path(key);
        match std::fs::read(&path) {
            Err(e) if e.kind() == std::io::ErrorKind::NotFound => Lookup::Miss,
            Err(e) => Lookup::Damaged(format!("{}: cannot read it: {e}", path.display())),
            Ok(bytes) => match decode(&bytes, width, height) {
                Ok(px) => Lookup::Hit(px),
                Err(why) => Lookup::Damaged(format!("{}: {why}", path.display())),
            },
        }
    }

    pub fn load(&self, key: &str, width: u32, height: u32) -> Option<Vec<[f32; 4]>> {
        match self.lookup(key, width, height) {
            Lookup::Hit(px) => Some(px),
            _ => None,
        }
    }

    /// The lock file of an entry.
    pub fn lock_path(&self, key: &str) -> PathBuf {
        self.dir.join("references").join(format!("{key}.lock"))
    }

    /// Takes the entry's lock, waiting while another process holds it (`waiting` is called
    /// once before the wait, to say so). Released when the returned guard drops or the
    /// process ends, however it ends.
    pub fn lock(&self, key: &str, waiting: impl FnOnce()) -> Result<EntryLock> {
        let path = self.lock_path(key);
        let fail = |what: &str, e: std::io::Error| {
            anyhow::anyhow!("reference cache: cannot {what} {}: {e}", path.display())
        };
        if let Some(dir) = path.parent() {
            std::fs::create_dir_all(dir).map_err(|e| fail("create the folder of", e))?;
        }
        let file = std::fs::OpenOptions::new()
            .create(true)
            .truncate(false)
            .write(true)
            .open(&path)
            .map_err(|e| fail("open", e))?;
        match file.try_lock() {
            Ok(()) => {}
            Err(std::fs::TryLockError::WouldBlock) => {
                waiting();
                file.lock().map_err(|e| fail("lock", e))?;
            }
            Err(std::fs::TryLockError::Error(e)) => return Err(fail("lock", e)),
        }
        Ok(EntryLock { _file: file })
    }

    pub fn store(&self, key: &str, width: u32, height: u32, pixels: &[[f32; 4]]) -> Result<()> {
        anyhow::ensure!(
            pixels.len() == (width * height) as usize,
            "image of {width}x{height} has {} pixels",
            pixels.len()
        );
        let data: &[u8] = bytemuck::cast_slice(pixels);
        output::write_atomic(&self.path(key), |w| {
            w.write_all(MAGIC)?;
            w.write_all(&width.to_le_bytes())?;
            w.write_all(&height.to_le_bytes())?;
            w.write_all(&Sha256::digest(data))?;
            // Pixels as little-endian f32 on any host.
            for v in bytemuck::cast_slice::<_, f32>(pixels) {
                w.write_all(&v.to_le_bytes())?;
            }
            Ok(())
        })
    }
}

/// An entry's lock, held until dropped (or until the process ends).
pub struct EntryLock {
    _file: std::fs::File,
}

/// What the cache holds for a key.
#[derive(Debug, PartialEq)]
pub enum Lookup {
    Hit(Vec<[f32; 4]>),
    Miss,
    /// An entry that cannot be used (truncated, altered, another size): why, naming the file.
    Damaged(String),
}

const MAGIC: &[u8; 8] = b"FLKREF01";
const HEADER: usize = 8 + 4 + 4 + 32;

fn decode(bytes: &[u8], width: u32, height: u32) -> std::result::Result<Vec<[f32; 4]>, String> {
    if bytes.len() < HEADER || &bytes[..8] != MAGIC {
        return Err(format!(
            "expected a reference cache entry (tag {}), got {} bytes of something else",
            String::from_utf8_lossy(MAGIC),
            bytes.len()
        ));
    }
    let word = |at: usize| u32::from_le_bytes(bytes[at..at + 4].try_into().expect("4 bytes"));
    let (w, h) = (word(8), word(12));
    if (w, h) != (width, height) {
        return Err(format!("holds a {w}x{h} image, expected {width}x{height}"));
    }
    let data = &bytes[HEADER..];
    let expected = (w as usize) * (h as usize) * 16;
    if data.len() != expected {
        return Err(format!(
            "has {} bytes of pixels, expected {expected} (truncated?)",
            data.len()
        ));
    }
    if Sha256::digest(data).as_slice() != &bytes[16..HEADER] {
        return Err("its pixels do not match its SHA-256 checksum".into());
    }
    let floats: Vec<f32> =
        data.chunks_exact(4).map(|c| f32::from_le_bytes(c.try_into().expect("4 bytes"))).collect();
    Ok(floats.chunks_exact(4).map(|c| [c[0], c[1], c[2], c[3]]).collect())
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
                host_source: "h",
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
        let tmp = tempfile::tempdir().unwrap();
        let dir = tmp.path().to_path_buf();
        let cache = ReferenceCache::new(&dir);
        let px = vec![[1.0, 2.0, 3.0, 1.0]; 8 * 4];
        assert!(cache.load("k", 8, 4).is_none());
        cache.store("k", 8, 4, &px).unwrap();
        assert_eq!(cache.load("k", 8, 4).unwrap(), px);
        assert!(cache.load("k", 4, 8).is_none());
    }

    #[test]
    fn damaged_entries_are_named_never_used() {
        let tmp = tempfile::tempdir().unwrap();
        let dir = tmp.path().to_path_buf();
        let cache = ReferenceCache::new(&dir);
        let px: Vec<[f32; 4]> = (0..8 * 4).map(|i| [i as f32, 0.5, -1.0, 1.0]).collect();
        cache.store("k", 8, 4, &px).unwrap();
        let path = cache.path("k");
        let good = std::fs::read(&path).unwrap();
        assert_eq!(cache.lookup("k", 8, 4), Lookup::Hit(px));
        let damaged = |bytes: &[u8], why: &str| {
            std::fs::write(&path, bytes).unwrap();
            match cache.lookup("k", 8, 4) {
                Lookup::Damaged(e) => {
                    assert!(e.contains("k.ref") && e.contains(why), "{e}")
                }
                other => panic!("{why}: {other:?}"),
            }
        };
        damaged(&good[..good.len() - 5], "truncated");
        damaged(&good[..10], "something else");
        let mut flipped = good.clone();
        *flipped.last_mut().unwrap() ^= 1; // one bit of the last pixel
        damaged(&flipped, "checksum");
        let mut sized = good.clone();
        sized[8] = 9;
        damaged(&sized, "9x4");
        damaged(b"", "something else");
    }
}
