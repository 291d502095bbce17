//! The structs the termination cache shares with WGSL (gpu_struct!) have each field at the same byte offset and
//! the same size on both sides, as naga lays the WGSL declaration out; its program links to valid
//! WGSL.

use render::gpu_struct::layout_mismatches;
use termination::cache::{TcParams, TcRecord, TcVertex};

#[test]
fn shared_structs_have_one_layout() {
    for (name, found) in [
        ("TcParams", layout_mismatches::<TcParams>("")),
        ("TcRecord", layout_mismatches::<TcRecord>("")),
        ("TcVertex", layout_mismatches::<TcVertex>("")),
    ] {
        assert!(found.is_empty(), "{name}: {found:?}");
    }
}

#[test]
fn the_program_links_to_valid_wgsl() {
    termination::TerminationCache::program().check_links().unwrap_or_else(|e| panic!("{e}"));
}
