//! The structs the SSS pass shares with WGSL (gpu_struct!) have each field at the same byte offset and
//! the same size on both sides, as naga lays the WGSL declaration out; its program links to valid
//! WGSL.

use render::gpu_struct::layout_mismatches;
use sss::gpu::SssParams;

#[test]
fn shared_structs_have_one_layout() {
    {
        let (name, found) = ("SssParams", layout_mismatches::<SssParams>(""));
        assert!(found.is_empty(), "{name}: {found:?}");
    }
}

#[test]
fn the_program_links_to_valid_wgsl() {
    sss::gpu::program().check_links().unwrap_or_else(|e| panic!("{e}"));
}
