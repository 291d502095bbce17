// The MIP chain's layout and eq. 5.12's level (twin of render/src/sss/prefilter.rs): level k is
// the image halved k times, rounded up; the levels lie one after another in one buffer.

fn sss_level_size(width: u32, height: u32, k: u32) -> vec2u {
    var s = vec2u(width, height);
    for (var i = 0u; i < k; i++) {
        s = max((s + vec2u(1u)) / 2u, vec2u(1u));
    }
    return s;
}

fn sss_level_offset(width: u32, height: u32, k: u32) -> u32 {
    var offset = 0u;
    for (var i = 0u; i < k; i++) {
        let s = sss_level_size(width, height, i);
        offset += s.x * s.y;
    }
    return offset;
}

// Eq. 5.12 in pixels: l = ½ max(log2(A_s / a), 0), A_s = 2πr / (n pdf(r)) texels per sample.
fn sss_mip_level(r: f32, pdf_r: f32, n: u32, a: f32, levels: u32) -> f32 {
    let texels = max(6.2831855 * r / (f32(n) * pdf_r), 1e-30);
    return clamp(0.5 * log2(texels / a), 0.0, f32(levels - 1u));
}
