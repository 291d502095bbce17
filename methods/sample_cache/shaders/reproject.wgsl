// Forward reprojection (section 3.1) with slot reservation on the occupancy/visibility mask
// (listing 2, fixed). One thread per (source pixel, slot) of last frame's cache.

import package::scene_bindings::{frame};
import package::scene_geometry::{NO_HIT};
import package::pt_scene::{project_offset};
import package::sample_cache_bindings::{dst_slots, pixel_atomics, src_mask, src_slots, ssc, ssc_work};
import package::sample_cache::storage::{SSC_ATOMICS, SSC_BACKGROUND_DEPTH, SSC_NO_DEPTH, SSC_DROPPED, SSC_REPROJECTED, SSC_WMAX, SSC_WMAX_ACC, SSC_WMIN, SSC_WMIN_ACC, ssc_background_dir, ssc_full, ssc_is_background, ssc_pixels, ssc_surface, ssc_visible_slots};
import package::sample_cache::slope::{ssc_closer, ssc_slope};
import package::kernel::{outside_image};

// Listing 2 as printed `break`s after the first try whatever its outcome; the text says a lost
// race retries on another slot while any remain. Here the loop only ends on success or when no
// free slot is left; every failed try ORs its bit into `m`, so candidates strictly shrink.
// Visible samples have priority (listing 2 lets a visible sample overwrite an invisible one in a
// full pixel): they reserve in a pass of their own before the invisible ones, so an invisible
// sample only ever takes a slot no visible sample wanted. Listing 2's overwrite within one pass
// races: a visible sample could take the slot an invisible one had just reserved while free
// slots remained, and both wrote it. Returns the slot or NO_HIT.
fn ssc_try_reserve(pixel: u32, visible: bool) -> u32 {
    let n = ssc.slots;
    let full = ssc_full();
    var m = atomicLoad(&pixel_atomics[SSC_ATOMICS * pixel]);
    loop {
        let candidates = ~m & full;
        if candidates == 0u {
            return NO_HIT;
        }
        let i = firstTrailingBit(candidates);
        let o_bit = 1u << i;
        let s_val = o_bit | select(0u, 1u << (i + n), visible);
        let previous = atomicOr(&pixel_atomics[SSC_ATOMICS * pixel], s_val);
        m = previous | s_val;
        if (previous & o_bit) == 0u {
            return i;
        }
    }
    return NO_HIT;
}

// Starts the frame's importance bounds: last frame's become this frame's bucket bounds.
@compute @workgroup_size(1, 1, 1)
fn begin_main() {
    atomicStore(&ssc_work[SSC_WMIN], atomicLoad(&ssc_work[SSC_WMIN_ACC]));
    atomicStore(&ssc_work[SSC_WMAX], atomicLoad(&ssc_work[SSC_WMAX_ACC]));
    atomicStore(&ssc_work[SSC_WMIN_ACC], 0xffffffffu);
    atomicStore(&ssc_work[SSC_WMAX_ACC], 0u);
}

// One thread per (source pixel, slot) of last frame's cache; moves the samples whose visibility
// bit is `visible_pass` (two passes, visible first: see ssc_try_reserve).
fn ssc_reserve(id: vec3u, visible_pass: bool) {
    if outside_image(id, ssc.width, ssc.height) || id.z >= ssc.slots {
        return;
    }
    let source = id.y * ssc.width + id.x;
    let s = id.z;
    let mask = src_mask[source];
    if ((mask >> s) & 1u) == 0u {
        return;
    }
    let visible = ((mask >> (s + ssc.slots)) & 1u) != 0u;
    if visible != visible_pass {
        return;
    }
    let slot = src_slots[s * ssc_pixels() + source];
    let eye = frame.camera.position;
    var image: vec2f;
    var depth = SSC_BACKGROUND_DEPTH;
    if ssc_is_background(slot.hit) {
        image = project_offset(frame.camera, ssc_background_dir(slot.hit));
    } else {
        let p = ssc_surface(slot.hit).position;
        image = project_offset(frame.camera, p - eye);
        depth = length(p - eye);
    }
    let size = vec2f(f32(ssc.width), f32(ssc.height));
    if !(all(image >= vec2f(0.0)) && all(image < size)) {
        atomicAdd(&ssc_work[SSC_DROPPED], 1u);
        return;
    }
    let target_pixel = min(vec2u(image), vec2u(ssc.width, ssc.height) - 1u);
    let t = target_pixel.y * ssc.width + target_pixel.x;
    let i = ssc_try_reserve(t, visible);
    if i == NO_HIT {
        atomicAdd(&ssc_work[SSC_DROPPED], 1u);
        return;
    }
    dst_slots[i * ssc_pixels() + t] = slot;
    if visible {
        atomicMax(&pixel_atomics[SSC_ATOMICS * t + 1u], bitcast<u32>(depth));
    }
    atomicAdd(&ssc_work[SSC_REPROJECTED], 1u);
}

@compute @workgroup_size(8, 8, 1)
fn reserve_visible_main(@builtin(global_invocation_id) id: vec3u) {
    ssc_reserve(id, true);
}

@compute @workgroup_size(8, 8, 1)
fn reserve_invisible_main(@builtin(global_invocation_id) id: vec3u) {
    ssc_reserve(id, false);
}

// The paper's closest-depth texture (section 3.4), per pixel after the reservation: the depth of
// its closest visible sample and that sample's Δn (eq. 1), which retrace_main reads over 3x3.
// The paper packs (depth, Δn) into one 64-bit atomicMin during reprojection; WGSL has no 64-bit
// atomics, so this pass reads the pixel's reserved samples instead (exact, no packing). Ties in
// depth keep the smaller Δn, so the result does not depend on the slots the race gave.
@compute @workgroup_size(8, 8, 1)
fn closest_main(@builtin(global_invocation_id) id: vec3u) {
    if outside_image(id, ssc.width, ssc.height) || ssc.retrace != 2u {
        return;
    }
    let pixels = ssc_pixels();
    let p = id.y * ssc.width + id.x;
    let eye = frame.camera.position;
    let vis = ssc_visible_slots(atomicLoad(&pixel_atomics[SSC_ATOMICS * p]));
    var closest = vec2f(SSC_NO_DEPTH, 0.0);
    for (var s = 0u; s < ssc.slots; s++) {
        if ((vis >> s) & 1u) == 0u {
            continue;
        }
        let hit = dst_slots[s * pixels + p].hit;
        var sample = vec2f(SSC_BACKGROUND_DEPTH, 0.0);
        if !ssc_is_background(hit) {
            let sp = ssc_surface(hit);
            let d = sp.position - eye;
            let t = length(d);
            sample = vec2f(t, ssc_slope(t, abs(dot(sp.geometric_normal, d / t)), ssc.pixel_diagonal_angle));
        }
        if ssc_closer(sample, closest) {
            closest = sample;
        }
    }
    atomicStore(&pixel_atomics[SSC_ATOMICS * p + 3u], bitcast<u32>(closest.x));
    atomicStore(&pixel_atomics[SSC_ATOMICS * p + 4u], bitcast<u32>(closest.y));
}
