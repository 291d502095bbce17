// The hybrid pass's own entries (render's hybrid.rs, Sec. 5.3.2): the setup registers each 8x8
// tile's technique (1: AFIS, 0: separable), P4 copies the AFIS tiles' result from buffer one
// (the separable intermediate, which P1 wrote there) into buffer two (`scattered`).

import package::sss_types::SssParams;

@group(0) @binding(0) var<storage, read> params: SssParams;
@group(0) @binding(1) var<storage, read> irradiance: array<vec4f>;
@group(0) @binding(2) var<storage, read_write> tiles: array<u32>;

// One invocation per tile: AFIS where some SSS pixel's sampled d (d_sample · w) reaches the
// rule's bound (the separable taps' outermost gap would exceed its pixels there).
@compute @workgroup_size(8, 8, 1)
fn sss_hybrid_setup(@builtin(global_invocation_id) id: vec3u) {
    let tiles_x = (params.width + 7u) / 8u;
    let tiles_y = (params.height + 7u) / 8u;
    if id.x >= tiles_x || id.y >= tiles_y {
        return;
    }
    var technique = 0u;
    // 64 pixels: a bounded loop.
    for (var k = 0u; k < 64u; k++) {
        let x = id.x * 8u + (k & 7u);
        let y = id.y * 8u + (k >> 3u);
        if x < params.width && y < params.height {
            let w = irradiance[y * params.width + x].w;
            if w > 0.0 && params.d_px.w * w >= params.hybrid_min_d {
                technique = 1u;
            }
        }
    }
    tiles[id.y * tiles_x + id.x] = technique;
}
