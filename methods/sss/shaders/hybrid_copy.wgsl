// P4 of the hybrid pass (render's hybrid.rs, Sec. 5.3.2): the AFIS tiles' result, written by P1
// into buffer one (the separable intermediate), copied into buffer two (`scattered`); the
// separable tiles' pixels are P3's.

import package::sss_types::SssParams;
import package::kernel::{outside_image};

@group(0) @binding(0) var<storage, read> params: SssParams;
@group(0) @binding(1) var<storage, read> intermediate: array<vec4f>;
@group(0) @binding(2) var<storage, read_write> scattered: array<vec4f>;
@group(0) @binding(3) var<storage, read> tiles: array<u32>;

@compute @workgroup_size(8, 8, 1)
fn sss_hybrid_copy(@builtin(global_invocation_id) id: vec3u, @builtin(workgroup_id) tile: vec3u) {
    if outside_image(id, params.width, params.height) {
        return;
    }
    if tiles[tile.y * ((params.width + 7u) / 8u) + tile.x] != 1u {
        return;
    }
    let pixel = id.y * params.width + id.x;
    scattered[pixel] = intermediate[pixel];
}
