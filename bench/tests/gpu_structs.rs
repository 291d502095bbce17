//! The bench's structs shared by Rust and WGSL (gpu_struct!) have each field at the same byte
//! offset and the same size on both sides, as naga lays the WGSL declaration out.

use bench::SgBvh2Node;

#[test]
fn shared_structs_have_one_layout() {
    let found = render::gpu_struct::layout_mismatches::<SgBvh2Node>("");
    assert!(found.is_empty(), "SgBvh2Node: {found:?}");
}
