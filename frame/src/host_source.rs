//! The host code a reference depends on: a hash of the sources of the crates that shape the
//! image on the CPU (the light table and its CDF, material and scene packing, the media, the
//! reference's own systems), computed by frame/build.rs when the crate is built. It is part of
//! the reference cache's key, so a reference rendered by other host code is never served.
//! Any edit under those folders changes it and renders every reference anew: coarse, but a
//! stale reference is impossible.

mod sources;

pub use sources::{HOST_SOURCES, hash_files, host_files};

/// The hash of [`HOST_SOURCES`] as this binary was built.
pub const HASH: &str = env!("FLICKER_HOST_SOURCE_HASH");

#[cfg(test)]
mod tests {
    use super::*;
    use crate::reference_cache::{Lookup, ReferenceCache, ReferenceKey};
    use std::path::{Path, PathBuf};

    fn root() -> PathBuf {
        Path::new(env!("CARGO_MANIFEST_DIR")).parent().expect("workspace root").to_path_buf()
    }

    fn read(root: &Path) -> impl FnMut(&str) -> Vec<u8> + '_ {
        move |f: &str| std::fs::read(root.join(f)).expect("a host source")
    }

    #[test]
    fn the_compiled_hash_is_that_of_the_sources_on_disk() {
        let root = root();
        let files = host_files(&root, HOST_SOURCES);
        for f in [
            "render/src/lights.rs",
            "render/src/materials.rs",
            "media/src/medium.rs",
            "frame/src/reference.rs",
        ] {
            assert!(files.iter().any(|g| g == f), "{f} is not hashed");
        }
        assert_eq!(hash_files(&files, &mut read(&root)), HASH);
    }

    /// A host-side constant changes (the light table's kind of a triangle light): the hash, and
    /// with it the reference's key, changes, and the reference stored under the old key misses.
    #[test]
    fn a_changed_host_constant_misses_the_cached_reference() {
        let root = root();
        let files = host_files(&root, HOST_SOURCES);
        let changed = hash_files(&files, &mut |f| {
            let bytes = std::fs::read(root.join(f)).expect("a host source");
            if f != "render/src/lights.rs" {
                return bytes;
            }
            let text = String::from_utf8(bytes).expect("utf-8");
            assert!(text.contains("const TRIANGLE: u32 = 3;"));
            text.replace("const TRIANGLE: u32 = 3;", "const TRIANGLE: u32 = 4;").into_bytes()
        });
        assert_ne!(changed, HASH);

        let tmp = tempfile::tempdir().unwrap();
        let dir = tmp.path().to_path_buf();
        let cache = ReferenceCache::new(&dir);
        let scene = render::scene::SceneDesc::default();
        let key = |host: &str| {
            ReferenceCache::key(
                &scene,
                &ReferenceKey {
                    width: 2,
                    height: 1,
                    spp: 4,
                    seed: 1,
                    max_depth: 3,
                    rr_start_depth: 3,
                    adapter: "a",
                    shader_source: "s",
                    host_source: host,
                },
            )
        };
        cache.store(&key(HASH), 2, 1, &[[1.0; 4]; 2]).unwrap();
        assert!(matches!(cache.lookup(&key(HASH), 2, 1), Lookup::Hit(_)));
        assert!(matches!(cache.lookup(&key(&changed), 2, 1), Lookup::Miss));
    }
}
