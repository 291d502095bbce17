// Primary ray tracing (sections 3.2 and 3.4) after reservation, in three dispatches.
// retrace_main (per pixel): canonical slot order, choice of the samples to retrace (single /
// multi / adaptive slope test), density control towards n_target ± δ over 3x3, the retrace list.
// retrace_list_main (per ray): visibility retrace. finish_main (per pixel): new samples for holes
// and density, final mask, (adaptive shading) the importance histogram. A pixel's thread owns its
// slots and mask; neighbours are read only through the reservation atomics, written no more.

import package::scene_bindings::{frame};
import package::scene_geometry::{NO_HIT, sg_rays_traced, trace_closest};
import package::pt_sampling::{rng_next, rng_next2, rng_seed};
import package::pt_lights::{FAR};
import package::pt_scene::{camera_ray_direction};
import package::sample_cache_types::{SscSlot};
import package::sample_cache_bindings::{dst_mask, dst_slots, pixel_atomics, ssc, ssc_out, ssc_work};
import package::sample_cache::storage::{SSC_ALL_RAYS, SSC_ATOMICS, SSC_BASE, SSC_FLAGGED, SSC_FLAG_BASE, SSC_FLAG_HOLE, SSC_FLAG_SLOPE, SSC_HISTOGRAM, SSC_LIST, SSC_MAX_SLOTS, SSC_NEW, SSC_OCCUPIED, SSC_PURGED, SSC_RAYS, SSC_RETRACE_COUNT, SSC_VISIBLE, SSC_WMAX_ACC, SSC_WMIN_ACC, ssc_full, ssc_is_background, ssc_less, ssc_list_index, ssc_pack_background, ssc_pack_hit, ssc_pixels, ssc_visible_slots};
import package::sample_cache::slope::{ssc_consistent};
import package::sample_cache::selection::{ssc_base_index, ssc_bucket, ssc_forced_shade, ssc_importance, ssc_is_base_pixel, ssc_nth_bit, ssc_verify};
import package::kernel::{outside_image};

// Jitter stays this far inside the pixel so that round-off never reprojects a sample of a static
// view into a neighbour (a sample exactly on a pixel border would flip sides).
const SSC_JITTER_INSET: f32 = 1.0e-3;

fn ssc_new_sample(pixel: vec2u, rng: ptr<function, u32>) -> vec4u {
    let jitter = mix(vec2f(SSC_JITTER_INSET), vec2f(1.0 - SSC_JITTER_INSET), rng_next2(rng));
    let eye = frame.camera.position;
    let dir = camera_ray_direction(frame.camera, vec2f(pixel) + jitter);
    let hit = trace_closest(eye, dir, FAR);
    if hit.instance == NO_HIT {
        return ssc_pack_background(dir);
    }
    return ssc_pack_hit(hit);
}

fn ssc_swap_bits(bits: u32, i: u32, j: u32) -> u32 {
    let a = (bits >> i) & 1u;
    let b = (bits >> j) & 1u;
    return (bits & ~((1u << i) | (1u << j))) | (a << j) | (b << i);
}

@compute @workgroup_size(8, 8, 1)
fn retrace_main(@builtin(global_invocation_id) id: vec3u) {
    if outside_image(id, ssc.width, ssc.height) {
        return;
    }
    let width = ssc.width;
    let pixels = ssc_pixels();
    let n = ssc.slots;
    let p = id.y * width + id.x;
    var rng = rng_seed(vec2u(frame.seed_lo, frame.seed_hi), frame.frame, p, 0x55c0u);

    // Gather the reserved slots and sort them into the canonical order (the slots a sample won
    // depend on the race of the reservation; the order of a pixel's samples must not).
    let m = atomicLoad(&pixel_atomics[SSC_ATOMICS * p]);
    var hits: array<vec4u, SSC_MAX_SLOTS>;
    var rads: array<vec4f, SSC_MAX_SLOTS>;
    var vis = 0u;
    var k = 0u;
    for (var s = 0u; s < n; s++) {
        if ((m >> s) & 1u) != 0u {
            let slot = dst_slots[s * pixels + p];
            hits[k] = slot.hit;
            rads[k] = slot.radiance;
            if ((m >> (s + n)) & 1u) != 0u {
                vis |= 1u << k;
            }
            k++;
        }
    }
    for (var i = 1u; i < k; i++) {
        var j = i;
        while j > 0u && ssc_less(hits[j], hits[j - 1u]) {
            let h = hits[j]; hits[j] = hits[j - 1u]; hits[j - 1u] = h;
            let r = rads[j]; rads[j] = rads[j - 1u]; rads[j - 1u] = r;
            vis = ssc_swap_bits(vis, j, j - 1u);
            j--;
        }
    }

    // 3x3 neighbourhood: visible-sample density, the farthest visible depth, and eq. 2 from each
    // neighbour's closest visible sample (depth, Δn; closest_main) to this pixel's farthest.
    var neighbour_visible = 0u;
    var neighbours = 0u;
    var t_max_bits = 0u;
    let own_far = bitcast<f32>(atomicLoad(&pixel_atomics[SSC_ATOMICS * p + 1u]));
    var far_side = false;
    for (var dy = -1; dy <= 1; dy++) {
        for (var dx = -1; dx <= 1; dx++) {
            let q = vec2i(id.xy) + vec2i(dx, dy);
            if q.x < 0 || q.y < 0 || q.x >= i32(width) || q.y >= i32(ssc.height) {
                continue;
            }
            let qi = u32(q.y) * width + u32(q.x);
            let mq = atomicLoad(&pixel_atomics[SSC_ATOMICS * qi]);
            neighbour_visible += countOneBits(ssc_visible_slots(mq));
            neighbours++;
            t_max_bits = max(t_max_bits, atomicLoad(&pixel_atomics[SSC_ATOMICS * qi + 1u]));
            let t_q = bitcast<f32>(atomicLoad(&pixel_atomics[SSC_ATOMICS * qi + 3u]));
            let slope_q = bitcast<f32>(atomicLoad(&pixel_atomics[SSC_ATOMICS * qi + 4u]));
            far_side = far_side || !ssc_consistent(t_q, own_far, slope_q, ssc.epsilon1);
        }
    }
    let density = f32(neighbour_visible) / f32(neighbours);

    // 1. Which samples to retrace.
    let all_k = (1u << k) - 1u;
    var trace_set = 0u;
    var flags = 0u;
    let mode = ssc.retrace;
    if mode == 0u {
        if k > 0u {
            trace_set = 1u << (ssc.frame % k);
        }
    } else if mode == 1u {
        trace_set = all_k;
    } else {
        if vis == 0u {
            flags |= SSC_FLAG_HOLE;
        } else {
            // Eq. 2 between this pixel and each 3x3 neighbour, both ways (section 3.4; each pair
            // is at most two pixel diagonals apart, the span App. A allows for): this pixel's
            // closest sample against the neighbourhood's farthest (the raised side of an edge),
            // and each neighbour's closest against this pixel's farthest (the far side). So a
            // pixel that holds only far samples beside a raised one is retraced too, and an
            // occluder's edge spreads one pixel a frame instead of waiting for the base rate.
            let t_own = bitcast<f32>(atomicLoad(&pixel_atomics[SSC_ATOMICS * p + 3u]));
            let slope_own = bitcast<f32>(atomicLoad(&pixel_atomics[SSC_ATOMICS * p + 4u]));
            if far_side || !ssc_consistent(t_own, bitcast<f32>(t_max_bits), slope_own, ssc.epsilon1) {
                flags |= SSC_FLAG_SLOPE;
            }
        }
        if ssc_is_base_pixel(id.xy) {
            flags |= SSC_FLAG_BASE;
        }
        if (flags & (SSC_FLAG_SLOPE | SSC_FLAG_HOLE)) != 0u {
            trace_set = all_k;
        } else if (flags & SSC_FLAG_BASE) != 0u && k > 0u {
            trace_set = 1u << ssc_base_index(k);
        }
    }

    // 2. Density control: when the 3x3 density is out of n_target ± δ, the pixel moves its own
    // visible count to n_target (at least one sample either way): purge visible samples at
    // random (the count is of visible samples), never the last one, or plan new samples. A pixel above n_target + δ purges even inside a
    // tolerable neighbourhood (twin of density.rs, which says why).
    let n_target = ssc.n_target;
    let delta = ssc.delta;
    var alive = all_k;
    var to_add = 0u;
    var purged = 0u;
    let own = f32(countOneBits(vis));
    if density < n_target - delta {
        to_add = u32(max(round(n_target) - own, 1.0));
    } else if density > n_target + delta || own > n_target + delta {
        let to_purge = u32(max(own - round(n_target), 1.0));
        for (var j = 0u; j < to_purge; j++) {
            let candidates = alive & vis;
            let c = countOneBits(candidates);
            if c <= 1u {
                break;
            }
            let r = min(u32(rng_next(&rng) * f32(c)), c - 1u);
            var bits = candidates;
            for (var skip = 0u; skip < r; skip++) {
                bits &= bits - 1u;
            }
            alive &= ~(1u << firstTrailingBit(bits));
            purged++;
        }
    }

    // Compact the survivors into slots 0..ka and queue the chosen ones for retracing: the rays
    // are traced by retrace_list_main, one thread per ray, so that a pixel retracing all its
    // samples does not hold up its SIMD neighbours that retrace none.
    var ka = 0u;
    var alive_vis = 0u;
    for (var i = 0u; i < k; i++) {
        if ((alive >> i) & 1u) != 0u {
            dst_slots[ka * pixels + p] = SscSlot(hits[i], rads[i]);
            alive_vis |= ((vis >> i) & 1u) << ka;
            if ((trace_set >> i) & 1u) != 0u {
                let at = atomicAdd(&ssc_work[SSC_RETRACE_COUNT], 1u);
                atomicStore(&ssc_work[SSC_LIST + at], ka * pixels + p);
            }
            ka++;
        }
    }
    dst_mask[p] = ((1u << ka) - 1u) | (alive_vis << n);
    ssc_out[p].flags = flags;
    // Carried to finish_main: how many new samples the density control asks for.
    ssc_out[p].rays = to_add;
    atomicAdd(&ssc_work[SSC_PURGED], purged);
    if (flags & SSC_FLAG_SLOPE) != 0u {
        atomicAdd(&ssc_work[SSC_FLAGGED], 1u);
    }
}

// 3. Retrace one queued sample: its result goes to the pixel's third atomic word.
// One thread per entry: dispatched indirectly with the list's length (list_dispatch.wgsl).
@compute @workgroup_size(64, 1, 1)
fn retrace_list_main(@builtin(global_invocation_id) id: vec3u, @builtin(num_workgroups) groups: vec3u) {
    let pixels = ssc_pixels();
    let index = ssc_list_index(id, groups);
    if index >= atomicLoad(&ssc_work[SSC_RETRACE_COUNT]) {
        return;
    }
    let entry = atomicLoad(&ssc_work[SSC_LIST + index]);
    let p = entry % pixels;
    let s = entry / pixels;
    let visible = ssc_verify(dst_slots[entry].hit);
    atomicAdd(&ssc_work[SSC_ALL_RAYS], sg_rays_traced);
    atomicOr(&pixel_atomics[SSC_ATOMICS * p + 2u], (1u << (s + 16u)) | select(0u, 1u << s, visible));
}

// 4. Per pixel: apply the retrace results, give a pixel without a visible sample a new one,
// add the samples the density control asked for, write the final mask and the histogram.
@compute @workgroup_size(8, 8, 1)
fn finish_main(@builtin(global_invocation_id) id: vec3u) {
    if outside_image(id, ssc.width, ssc.height) {
        return;
    }
    let pixels = ssc_pixels();
    let n = ssc.slots;
    let p = id.y * ssc.width + id.x;
    var rng = rng_seed(vec2u(frame.seed_lo, frame.seed_hi), frame.frame, p, 0x55c1u);
    let provisional = dst_mask[p];
    var kf = countOneBits(provisional & ssc_full());
    let results = atomicLoad(&pixel_atomics[SSC_ATOMICS * p + 2u]);
    let traced = results >> 16u;
    var out_vis = (((provisional >> n) & ~traced) | (results & traced)) & ((1u << kf) - 1u);
    var rays = countOneBits(traced);
    var to_add = ssc_out[p].rays;
    // At least one visible sample per pixel: a pixel left without one gets a new sample
    // (taking the last failed sample's place when the pixel is full).
    if out_vis == 0u {
        to_add = max(to_add, 1u);
    }
    var added = 0u;
    for (var j = 0u; j < to_add; j++) {
        var at = kf;
        if kf >= n {
            let invisible = ((1u << kf) - 1u) & ~out_vis;
            if invisible == 0u {
                break;
            }
            at = firstLeadingBit(invisible);
        } else {
            kf++;
        }
        dst_slots[at * pixels + p] = SscSlot(ssc_new_sample(id.xy, &rng), vec4f(0.0));
        out_vis |= 1u << at;
        rays++;
        added++;
    }
    dst_mask[p] = ((1u << kf) - 1u) | (out_vis << n);
    ssc_out[p].rays = rays;

    atomicAdd(&ssc_work[SSC_RAYS], rays);
    atomicAdd(&ssc_work[SSC_ALL_RAYS], sg_rays_traced);
    atomicAdd(&ssc_work[SSC_NEW], added);
    atomicAdd(&ssc_work[SSC_VISIBLE], countOneBits(out_vis));
    atomicAdd(&ssc_work[SSC_OCCUPIED], kf);

    // Adaptive shading: histogram of the importance of every visible sample that the base rate
    // (or the first shade of a pixel with no shaded visible sample) does not already shade.
    if ssc.shading == 1u {
        let base = ssc_forced_shade(id.xy, p, out_vis);
        if base != NO_HIT {
            atomicAdd(&ssc_work[SSC_BASE], 1u);
        }
        for (var i = 0u; i < kf; i++) {
            if ((out_vis >> i) & 1u) == 0u || i == base {
                continue;
            }
            let w = ssc_importance(dst_slots[i * pixels + p].radiance.w);
            atomicMin(&ssc_work[SSC_WMIN_ACC], bitcast<u32>(w));
            atomicMax(&ssc_work[SSC_WMAX_ACC], bitcast<u32>(w));
            atomicAdd(&ssc_work[SSC_HISTOGRAM + ssc_bucket(w)], 1u);
        }
    }
}
