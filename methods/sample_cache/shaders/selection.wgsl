// What the retrace, shading-rate and reconstruction passes share: the 4x4 block's base pixel, the
// visibility check of a stored sample, importance and its log-spaced buckets, bit selection.

import package::scene_bindings::{frame};
import package::scene_geometry::{NO_HIT, trace_any};
import package::pt_lights::{FAR};
import package::sample_cache_bindings::{dst_slots, ssc, ssc_work};
import package::sample_cache::storage::{SSC_WMAX, SSC_WMIN, ssc_background_dir, ssc_is_background, ssc_pixels, ssc_surface};

// The 4x4 block's base pixel this frame: the block position visits all b*b pixels in turn.
fn ssc_is_base_pixel(pixel: vec2u) -> bool {
    let b = ssc.base_block;
    let k = ssc.frame % (b * b);
    return pixel.x % b == k % b && pixel.y % b == k / b;
}

// Round-robin index of the base sample of a base pixel, among `count` candidates.
fn ssc_base_index(count: u32) -> u32 {
    let b = ssc.base_block;
    return (ssc.frame / (b * b)) % max(count, 1u);
}

// Adaptive shading's sample of pixel p (visible slots `vis`) that is shaded outside the
// importance budget, or NO_HIT: the base rate's round-robin sample on the block's base pixel,
// else the first visible sample when none of them has been shaded yet, so that every pixel with
// a visible sample reconstructs from a shaded one (a pixel of only new samples would otherwise
// show nothing: a new sample's c_s = 0 is the top bucket, but the coin toss there may skip it).
// Read by the trace pass (histogram, count) and by select_main on the same state.
fn ssc_forced_shade(pixel: vec2u, p: u32, vis: u32) -> u32 {
    let nv = countOneBits(vis);
    if nv == 0u {
        return NO_HIT;
    }
    if ssc_is_base_pixel(pixel) {
        return ssc_nth_bit(vis, ssc_base_index(nv));
    }
    let pixels = ssc_pixels();
    for (var s = 0u; s < ssc.slots; s++) {
        if ((vis >> s) & 1u) != 0u && dst_slots[s * pixels + p].radiance.w > 0.0 {
            return NO_HIT;
        }
    }
    return firstTrailingBit(vis);
}

// Retrace from the eye towards the stored point (a shadow ray, section 3.2): visible when nothing
// is hit before (1 - ε0) of the way there; a background sample is visible when its ray escapes.
fn ssc_verify(hit: vec4u) -> bool {
    let eye = frame.camera.position;
    if ssc_is_background(hit) {
        return !trace_any(eye, ssc_background_dir(hit), FAR);
    }
    let d = ssc_surface(hit).position - eye;
    return !trace_any(eye, d, 1.0 - ssc.epsilon0);
}

// Log-spaced bucket (M buckets) of importance w between this frame's bounds (last frame's min
// and max): M - 1 = most important. Degenerate bounds (first frame) put everything in M - 1.
fn ssc_bucket(w: f32) -> u32 {
    let m = ssc.buckets;
    let lo = bitcast<f32>(atomicLoad(&ssc_work[SSC_WMIN]));
    let hi = bitcast<f32>(atomicLoad(&ssc_work[SSC_WMAX]));
    if !(lo > 0.0) || !(hi > lo) {
        return m - 1u;
    }
    let f = log(w / lo) / log(hi / lo);
    return u32(clamp(floor(f * f32(m)), 0.0, f32(m - 1u)));
}

fn ssc_importance(count: f32) -> f32 {
    return 1.0 / (1.0 + count);
}

// Index of the r-th set bit of `bits` (r counted from 0, lowest first).
fn ssc_nth_bit(bits: u32, r: u32) -> u32 {
    var b = bits;
    for (var skip = 0u; skip < r; skip++) {
        b &= b - 1u;
    }
    return firstTrailingBit(b);
}
