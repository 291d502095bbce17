//! The hash of the host code that shapes a reference (`frame::host_source::HASH`): the files
//! of `HOST_SOURCES` at build time. Cargo reruns this script whenever one of them changes, so
//! the compiled hash is always that of the sources the binary was built from.

include!("src/host_source/sources.rs");

fn main() {
    let manifest = std::path::PathBuf::from(std::env::var("CARGO_MANIFEST_DIR").expect("cargo"));
    let root = manifest.parent().expect("frame/ sits in the workspace root");
    for s in HOST_SOURCES {
        println!("cargo:rerun-if-changed={}", root.join(s).display());
    }
    let files = host_files(root, HOST_SOURCES);
    let hash = hash_files(&files, &mut |f| {
        std::fs::read(root.join(f)).unwrap_or_else(|e| panic!("{f}: {e}"))
    });
    println!("cargo:rustc-env=FLICKER_HOST_SOURCE_HASH={hash}");
}
