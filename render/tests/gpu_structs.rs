//! Every struct of render shared by Rust and WGSL (gpu_struct!) has each field at the same byte
//! offset and the same size on both sides, as naga lays the WGSL declaration out (each method
//! crate checks its own structs the same way, in its tests/gpu_structs.rs).

use render::bvh::{SgInstance, SgInstanceHeader, SgMesh, SgNode, SgTlasLeaf, SgTriangle, SgVertex};
use render::frame::{CameraFrame, Frame};
use render::gpu_struct::GpuStruct;
use render::lights::GpuLight;
use render::materials::GpuMaterial;
use render::path_tracer::GBufferTexel;

fn mismatches<T: GpuStruct>(deps: &str) -> Vec<String> {
    render::gpu_struct::layout_mismatches::<T>(deps)
}

#[test]
fn shared_structs_have_one_layout() {
    let camera = CameraFrame::WGSL;
    for (name, found) in [
        ("CameraFrame", mismatches::<CameraFrame>("")),
        ("Frame", mismatches::<Frame>(camera)),
        ("GpuMaterial", mismatches::<GpuMaterial>("")),
        ("GBufferTexel", mismatches::<GBufferTexel>("")),
        ("GpuLight", mismatches::<GpuLight>("")),
        ("SgNode", mismatches::<SgNode>("")),
        ("SgTriangle", mismatches::<SgTriangle>("")),
        ("SgTlasLeaf", mismatches::<SgTlasLeaf>("")),
        ("SgMesh", mismatches::<SgMesh>("")),
        ("SgVertex", mismatches::<SgVertex>("")),
        ("SgInstance", mismatches::<SgInstance>("")),
        ("SgInstanceHeader", mismatches::<SgInstanceHeader>("")),
    ] {
        assert!(found.is_empty(), "{name}: {found:?}");
    }
    let ray_batch = render::bvh::ray_batch_struct_mismatches();
    assert!(ray_batch.is_empty(), "ray batch: {ray_batch:?}");
}

render::gpu_struct! {
    /// WGSL aligns vec3f to 16 bytes, Rust's [f32; 3] to 4: `b` sits at 16 there, 12 here.
    struct Misaligned {
        a: [f32; 3] => "vec3f",
        b: [f32; 3] => "vec3f",
    }
}

#[test]
fn a_layout_mismatch_is_found() {
    let found = mismatches::<Misaligned>("");
    assert!(
        found.iter().any(|m| m.contains("Misaligned.b") && m.contains("offset 12")),
        "{found:?}"
    );
    let _ = Misaligned { a: [0.0; 3], b: [0.0; 3] };
}

#[test]
fn declarations_name_every_field() {
    assert_eq!(
        Frame::WGSL.lines().filter(|l| l.trim_end().ends_with(',')).count(),
        Frame::offsets().len(),
        "{}",
        Frame::WGSL
    );
    assert!(
        Frame::WGSL.contains("    max_depth: u32,")
            && Frame::WGSL.contains("    rr_start_depth: u32,")
    );
}
