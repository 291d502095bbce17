//! The structs the hash cache shares with WGSL (gpu_struct!) have each field at the same byte offset and
//! the same size on both sides, as naga lays the WGSL declaration out; its program links to valid
//! WGSL.

use hash_cache::{HashCacheParams, HcRecord};
use render::gpu_struct::layout_mismatches;

#[test]
fn shared_structs_have_one_layout() {
    for (name, found) in [
        ("HashCacheParams", layout_mismatches::<HashCacheParams>("")),
        ("HcRecord", layout_mismatches::<HcRecord>("")),
    ] {
        assert!(found.is_empty(), "{name}: {found:?}");
    }
}

#[test]
fn the_program_links_to_valid_wgsl() {
    hash_cache::HashCache::program().check_links().unwrap_or_else(|e| panic!("{e}"));
}
