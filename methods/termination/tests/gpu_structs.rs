//! The structs the termination cache shares with WGSL (gpu_struct!) have each field at the same byte offset and
//! the same size on both sides, as naga lays the WGSL declaration out.

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
