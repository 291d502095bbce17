// Eq. 5.12's MIP level (twin of sss::prefilter::level); the chain's layout per level
// (offset, width, height) comes in SssParams::mip, computed on the host.

// Eq. 5.12 in pixels: l = ½ max(log2(A_s / a), 0), A_s = 2πr / (n pdf(r)) texels per sample.
fn sss_mip_level(r: f32, pdf_r: f32, n: u32, a: f32, levels: u32) -> f32 {
    let texels = max(6.2831855 * r / (f32(n) * pdf_r), 1e-30);
    return clamp(0.5 * log2(texels / a), 0.0, f32(levels - 1u));
}
