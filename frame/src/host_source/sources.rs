// Shared by frame/build.rs (`include!`) and `frame::host_source`: which files shape a reference
// on the host, and their hash. Plain std and sha2, no crate-local items.

/// The folders (relative to the workspace root) whose files shape a path-traced reference
/// besides what its key already holds (the scene, the settings, the WGSL, the adapter): the
/// scene's types (`scene`), its packing for the GPU (`render`: materials, the light table and
/// its CDF, the camera, the BVH), the media and the random walk's passes (`media`), the
/// reference's systems and seed (`frame`), and the dependencies' versions (`Cargo.lock`).
pub const HOST_SOURCES: &[&str] = &[
    "render/src",
    "render/shaders",
    "scene/src",
    "media/src",
    "media/shaders",
    "frame/src",
    "Cargo.lock",
];

/// Every file under `sources` (a folder's files recursively, in path order), relative to `root`.
pub fn host_files(root: &std::path::Path, sources: &[&str]) -> Vec<String> {
    fn walk(root: &std::path::Path, rel: &str, out: &mut Vec<String>) {
        let path = root.join(rel);
        if path.is_dir() {
            let mut entries: Vec<String> = std::fs::read_dir(&path)
                .unwrap_or_else(|e| panic!("{}: {e}", path.display()))
                .map(|e| e.expect("a directory entry").file_name().to_string_lossy().into_owned())
                .collect();
            entries.sort();
            for name in entries {
                walk(root, &format!("{rel}/{name}"), out);
            }
        } else if path.is_file() {
            out.push(rel.to_string());
        } else {
            panic!("host source {} does not exist", path.display());
        }
    }
    let mut out = Vec::new();
    for s in sources {
        walk(root, s, &mut out);
    }
    out
}

/// SHA-256 over each file's relative path, length and bytes (`read` gives the bytes), as hex.
pub fn hash_files(files: &[String], read: &mut dyn FnMut(&str) -> Vec<u8>) -> String {
    use sha2::{Digest, Sha256};
    let mut h = Sha256::new();
    for f in files {
        let bytes = read(f);
        h.update(f.as_bytes());
        h.update((bytes.len() as u64).to_le_bytes());
        h.update(&bytes);
    }
    h.finalize().iter().map(|b| format!("{b:02x}")).collect()
}
