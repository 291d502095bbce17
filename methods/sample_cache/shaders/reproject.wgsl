// Forward reprojection (section 3.1) with slot reservation (listing 2, made deterministic).
// One thread per (source pixel, slot) of last frame's cache reserves by key; then one per pixel
// gathers the kept samples into its slots.

import package::scene_bindings::{frame};
import package::pt_sampling::{pcg_hash};
import package::pt_scene::{project_offset};
import package::sample_cache_bindings::{dst_slots, pixel_atomics, reserve_keys, src_mask, src_slots, ssc, ssc_work};
import package::sample_cache::storage::{SSC_ATOMICS, SSC_BACKGROUND_DEPTH, SSC_NO_DEPTH, SSC_DROPPED, SSC_REPROJECTED, SSC_WMAX, SSC_WMAX_ACC, SSC_WMIN, SSC_WMIN_ACC, ssc_background_dir, ssc_is_background, ssc_pixels, ssc_surface, ssc_visible_slots};
import package::sample_cache::slope::{ssc_closer, ssc_slope};
import package::kernel::{outside_image};

// Reservation by key (reservation.rs is the CPU twin). A sample's key is its visibility (0 =
// visible, so visible samples come first, listing 2's priority) over its index in last frame's
// cache XOR a per-frame mask (so that no source pixel or slot is preferred frame after frame).
// A pixel keeps the N lowest keys that reach it: N words per pixel (`reserve_keys`, layered as
// the slots) hold them sorted, inserted by a chain of atomics: at word i the key swaps with a
// larger one (keeping the smaller) and the larger moves on to word i + 1, until an empty word
// takes it or it falls off the end (dropped). Whatever order the threads run in, word i ends
// with the i-th lowest key: the kept samples, and their order, do not depend on scheduling.
// Listing 2's atomicOr race (any sample may win a full pixel) cannot give that. The words
// store the complement of the key and use atomicMax, so that the frame's clear to 0 empties
// them.
const SSC_KEY_INVISIBLE: u32 = 0x80000000u;
const SSC_KEY_INDEX: u32 = 0x3fffffffu;

fn ssc_key_mask() -> u32 {
    return pcg_hash(frame.frame ^ pcg_hash(frame.seed_lo ^ pcg_hash(frame.seed_hi))) & SSC_KEY_INDEX;
}

// Inserts `key` into pixel t's sorted words; false when it was dropped (the pixel holds N
// lower keys).
fn ssc_insert_key(t: u32, key: u32) -> bool {
    let pixels = ssc_pixels();
    var word = ~key;
    for (var i = 0u; i < ssc.slots; i++) {
        let previous = atomicMax(&reserve_keys[i * pixels + t], word);
        if previous == 0u {
            return true;
        }
        word = min(previous, word);
    }
    return false;
}

// Starts the frame's importance bounds: last frame's become this frame's bucket bounds.
@compute @workgroup_size(1, 1, 1)
fn begin_main() {
    atomicStore(&ssc_work[SSC_WMIN], atomicLoad(&ssc_work[SSC_WMIN_ACC]));
    atomicStore(&ssc_work[SSC_WMAX], atomicLoad(&ssc_work[SSC_WMAX_ACC]));
    atomicStore(&ssc_work[SSC_WMIN_ACC], 0xffffffffu);
    atomicStore(&ssc_work[SSC_WMAX_ACC], 0u);
}

// One thread per (source pixel, slot) of last frame's cache: the sample's target pixel and its
// key there.
@compute @workgroup_size(8, 8, 1)
fn reserve_main(@builtin(global_invocation_id) id: vec3u) {
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
    let index = s * ssc_pixels() + source;
    let slot = src_slots[index];
    let eye = frame.camera.position;
    var image: vec2f;
    if ssc_is_background(slot.hit) {
        image = project_offset(frame.camera, ssc_background_dir(slot.hit));
    } else {
        image = project_offset(frame.camera, ssc_surface(slot.hit).position - eye);
    }
    let size = vec2f(f32(ssc.width), f32(ssc.height));
    if !(all(image >= vec2f(0.0)) && all(image < size)) {
        atomicAdd(&ssc_work[SSC_DROPPED], 1u);
        return;
    }
    let target_pixel = min(vec2u(image), vec2u(ssc.width, ssc.height) - 1u);
    let t = target_pixel.y * ssc.width + target_pixel.x;
    let key = select(SSC_KEY_INVISIBLE, 0u, visible) | (index ^ ssc_key_mask());
    if !ssc_insert_key(t, key) {
        atomicAdd(&ssc_work[SSC_DROPPED], 1u);
    }
}

// Per pixel after reserve_main: its kept samples into slots 0.. in key order, the reserved mask
// (occupancy, visibility) and, for the slope test, the farthest visible depth.
@compute @workgroup_size(8, 8, 1)
fn gather_main(@builtin(global_invocation_id) id: vec3u) {
    if outside_image(id, ssc.width, ssc.height) {
        return;
    }
    let pixels = ssc_pixels();
    let n = ssc.slots;
    let p = id.y * ssc.width + id.x;
    let key_mask = ssc_key_mask();
    let eye = frame.camera.position;
    var m = 0u;
    var far = 0.0;
    for (var i = 0u; i < n; i++) {
        let word = atomicLoad(&reserve_keys[i * pixels + p]);
        if word == 0u {
            break;
        }
        let key = ~word;
        let slot = src_slots[(key & SSC_KEY_INDEX) ^ key_mask];
        dst_slots[i * pixels + p] = slot;
        m |= 1u << i;
        if (key & SSC_KEY_INVISIBLE) == 0u {
            m |= 1u << (i + n);
            if ssc.retrace == 2u {
                var depth = SSC_BACKGROUND_DEPTH;
                if !ssc_is_background(slot.hit) {
                    depth = length(ssc_surface(slot.hit).position - eye);
                }
                far = max(far, depth);
            }
        }
    }
    atomicStore(&pixel_atomics[SSC_ATOMICS * p], m);
    atomicStore(&pixel_atomics[SSC_ATOMICS * p + 1u], bitcast<u32>(far));
    atomicAdd(&ssc_work[SSC_REPROJECTED], countOneBits(m & ((1u << n) - 1u)));
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
