// World-space hash cache (HashCache of stable-sample-caching.txt §4-5): the passes of one frame.
// Built on the pass library, TAA's primary.wgsl and hash_key.wgsl.
//
//   hc_age      per slot:  evict cells not accessed for more than max_age frames; reset claims
//   hc_trace    per pixel: jittered primary ray, direct part of the pixel, key point (the first
//                          hit, or the first secondary hit), find-or-insert by linear probing,
//                          last access, claim (atomicMin of the pixel index)
//   hc_update   per pixel: the claimant of each cell (lowest pixel index: one writer, no float
//                          atomics, deterministic) traces one path from the key point and folds
//                          it into the cell's running mean
//   hc_resolve  per pixel: colour = direct + modulate * cell radiance
//
// A slot is 4 u32 in `slots`: checksum (0 = empty), last access (frame + 1), claim, home slot.
// Keys: 32-bit checksum + home slot replace the paper's 64-bit (last access, checksum) word, as
// WGSL has no 64-bit atomics: the checksum alone is claimed by compare-exchange, last access is
// a separate word every accessor stores the same value into.

import package::scene_bindings::{frame};
import package::scene_tables::{material};
import package::scene_geometry::{Hit, NO_HIT, sg_rays_traced, surface_point, trace_closest};
import package::pt_sampling::{hash_mix, rng_next, rng_next2, rng_seed};
import package::pt_bsdf::{bsdf_sample, make_bsdf};
import package::pt_lights::{FAR};
import package::pt_scene::{base_color_at, camera_ray_direction, escaped_radiance, offset_origin, orient};
import package::pt_integrator::{emitted_radiance, next_event, path_radiance};
import package::taa::primary::{primary_attributes};
import package::hash_cache_types::{HcRecord};
import package::hash_cache_bindings::{cell_radiance, colour_out, counters, hc, primary_out, records, slots};
import package::hash_cache::hash_key::{HC_EMPTY, HC_NONE, VoxelKey, hc_key, hc_level};
import package::kernel::{outside_image};

const HC_NEEDS_SAMPLE: u32 = 1u;
const HC_COUNTER_OCCUPIED: u32 = 0u;
const HC_COUNTER_EVICTED: u32 = 1u;
const HC_COUNTER_INSERTED: u32 = 2u;
const HC_COUNTER_FAILED: u32 = 3u;
const HC_COUNTER_UPDATES: u32 = 4u;
const HC_COUNTER_RAYS: u32 = 5u;      // rays traced by hc_trace and hc_update

@compute @workgroup_size(64, 1, 1)
fn hc_age(@builtin(global_invocation_id) id: vec3u) {
    let s = id.x;
    if s >= hc.capacity {
        return;
    }
    atomicStore(&slots[4u * s + 2u], HC_NONE);
    if atomicLoad(&slots[4u * s]) == HC_EMPTY {
        return;
    }
    if hc.frame - atomicLoad(&slots[4u * s + 1u]) > hc.max_age {
        atomicStore(&slots[4u * s], HC_EMPTY);
        atomicStore(&slots[4u * s + 1u], 0u);
        atomicStore(&slots[4u * s + 3u], 0u);
        cell_radiance[s] = vec4f(0.0);
        atomicAdd(&counters[HC_COUNTER_EVICTED], 1u);
    } else {
        atomicAdd(&counters[HC_COUNTER_OCCUPIED], 1u);
    }
}

// Slot of `key`, inserted if absent; HC_NONE when all probe_limit slots from home hold other
// keys. A read-only scan of the whole probe window first (holes left by eviction must not make
// a second copy of a key further along), then a compare-exchange walk in the same order: slots
// only go from empty to a key within the pass, so two threads with one key meet at one slot.
fn hc_find_or_insert(key: VoxelKey) -> u32 {
    for (var i = 0u; i < hc.probe_limit; i++) {
        let s = (key.home + i) % hc.capacity;
        if atomicLoad(&slots[4u * s]) == key.checksum {
            return s;
        }
    }
    for (var i = 0u; i < hc.probe_limit; i++) {
        let s = (key.home + i) % hc.capacity;
        let r = atomicCompareExchangeWeak(&slots[4u * s], HC_EMPTY, key.checksum);
        if r.exchanged {
            atomicStore(&slots[4u * s + 3u], key.home);
            atomicAdd(&counters[HC_COUNTER_INSERTED], 1u);
            return s;
        }
        if r.old_value == key.checksum {
            return s;
        }
        if r.old_value == HC_EMPTY {
            // Spurious failure of the weak exchange: try this slot again.
            i--;
        }
    }
    atomicAdd(&counters[HC_COUNTER_FAILED], 1u);
    return HC_NONE;
}

// Stores the pixel's record at the end of hc_trace and books the invocation's rays.
fn hc_store_record(index: u32, r: HcRecord) {
    records[index] = r;
    atomicAdd(&counters[HC_COUNTER_RAYS], sg_rays_traced);
}

@compute @workgroup_size(8, 8, 1)
fn hc_trace(@builtin(global_invocation_id) id: vec3u) {
    if outside_image(id, frame.width, frame.height) {
        return;
    }
    let index = id.y * frame.width + id.x;
    var rng = rng_seed(vec2u(frame.seed_lo, frame.seed_hi), frame.frame, index, frame.first_sample);
    let origin = frame.camera.position;
    let dir = camera_ray_direction(frame.camera, vec2f(id.xy) + hc.primary_jitter);
    let hit = trace_closest(origin, dir, FAR);
    primary_out[index] = primary_attributes(hit, origin, dir);
    var r: HcRecord;
    r.slot = HC_NONE;
    r.flags = 0u;
    r.modulate = vec3f(0.0);
    if hit.instance == NO_HIT {
        r.direct = escaped_radiance(dir, 0.0);
        hc_store_record(index, r);
        return;
    }
    let sp = surface_point(hit, origin, dir);
    let m = material(sp.material);
    let sh = orient(sp, -dir);
    r.direct = emitted_radiance(sp, m, dir, hit.t, 0.0);
    if hc.lookup == 0u {
        // The paper's HashCache: the first hit's outgoing radiance, albedo demodulated.
        r.key_hit = hc_pack_hit(hit);
        r.key_point = sp.position;
        r.key_normal = sh.ns;
        r.modulate = base_color_at(m, sp.uv);
        r.ray_origin = origin;
        r.ray_dir = dir;
        r.depth = 0u;
    } else {
        // Secondary bounce terminates into the cache at its hit.
        let bsdf = make_bsdf(base_color_at(m, sp.uv), m.metallic, m.roughness, m.specular);
        r.direct += next_event(sp.position, sh, bsdf, -dir, &rng);
        let bs = bsdf_sample(bsdf, sh.ns, -dir, rng_next(&rng), rng_next2(&rng));
        if !bs.valid || dot(bs.wi, sh.ng) <= 0.0 {
            hc_store_record(index, r);
            return;
        }
        let throughput = bs.f * (dot(sh.ns, bs.wi) / bs.pdf);
        let o2 = offset_origin(sp.position, sh.ng, bs.wi);
        let hit2 = trace_closest(o2, bs.wi, FAR);
        if hit2.instance == NO_HIT {
            r.direct += throughput * escaped_radiance(bs.wi, bs.pdf);
            hc_store_record(index, r);
            return;
        }
        let sp2 = surface_point(hit2, o2, bs.wi);
        r.direct += throughput * emitted_radiance(sp2, material(sp2.material), bs.wi, hit2.t, bs.pdf);
        r.key_hit = hc_pack_hit(hit2);
        r.key_point = sp2.position;
        r.key_normal = orient(sp2, -bs.wi).ns;
        r.modulate = throughput;
        r.ray_origin = o2;
        r.ray_dir = bs.wi;
        r.depth = 1u;
    }
    r.flags = HC_NEEDS_SAMPLE;
    // Voxel jitter, quantised to 16 bits so that the CPU reference sees the same value.
    var jrng = rng_seed(vec2u(hc.voxel_jitter_seed, frame.seed_hi), frame.frame, index, 0x7a3du);
    r.voxel_jitter = pack2x16unorm(rng_next2(&jrng));
    let to_point = r.key_point - origin;
    let distance = length(to_point);
    let level = hc_level(distance, dot(r.key_normal, to_point) / distance);
    let key = hc_key(r.key_point, r.key_normal, level, unpack2x16unorm(r.voxel_jitter));
    r.home = key.home;
    r.checksum = key.checksum;
    r.slot = hc_find_or_insert(key);
    if r.slot != HC_NONE {
        atomicStore(&slots[4u * r.slot + 1u], hc.frame);
        atomicMin(&slots[4u * r.slot + 2u], index);
    }
    // The update path continues this pixel's random stream.
    r.rng = hash_mix(rng ^ 0x9e3779b9u);
    hc_store_record(index, r);
}

// The key point's hit as stored in the record (t is not needed: surface_point rebuilds the
// point from the barycentrics).
fn hc_pack_hit(hit: Hit) -> vec4u {
    return vec4u(hit.instance, hit.primitive, bitcast<vec2u>(hit.barycentrics));
}

fn hc_unpack_hit(h: vec4u) -> Hit {
    return Hit(0.0, h.x, h.y, bitcast<vec2f>(h.zw));
}

// One estimate of the radiance leaving the key point towards the ray's origin, emission
// excluded (the pixel adds it): next-event estimation + one BSDF-sampled continuation. Starts
// from the hit hc_trace found (no second trace of the key ray).
fn hc_sample(r: HcRecord) -> vec3f {
    var rng = r.rng;
    let sp = surface_point(hc_unpack_hit(r.key_hit), r.ray_origin, r.ray_dir);
    let m = material(sp.material);
    let wo = -r.ray_dir;
    let sh = orient(sp, wo);
    let bsdf = make_bsdf(base_color_at(m, sp.uv), m.metallic, m.roughness, m.specular);
    var l = next_event(sp.position, sh, bsdf, wo, &rng);
    if r.depth + 1u <= frame.max_depth {
        let bs = bsdf_sample(bsdf, sh.ns, wo, rng_next(&rng), rng_next2(&rng));
        if bs.valid && dot(bs.wi, sh.ng) > 0.0 {
            let throughput = bs.f * (dot(sh.ns, bs.wi) / bs.pdf);
            l += throughput * path_radiance(offset_origin(sp.position, sh.ng, bs.wi), bs.wi, bs.pdf, r.depth + 1u, &rng);
        }
    }
    return l;
}

// Radiance divided by the albedo it will be multiplied with (first-hit lookup).
fn hc_demodulate(l: vec3f, albedo: vec3f) -> vec3f {
    return select(vec3f(0.0), l / albedo, albedo > vec3f(1.0e-4));
}

@compute @workgroup_size(8, 8, 1)
fn hc_update(@builtin(global_invocation_id) id: vec3u) {
    if outside_image(id, frame.width, frame.height) {
        return;
    }
    let index = id.y * frame.width + id.x;
    let r = records[index];
    if (r.flags & HC_NEEDS_SAMPLE) == 0u {
        return;
    }
    let claimant = r.slot != HC_NONE && atomicLoad(&slots[4u * r.slot + 2u]) == index;
    if r.slot != HC_NONE && !claimant {
        return;
    }
    atomicAdd(&counters[HC_COUNTER_UPDATES], 1u);
    var l = hc_sample(r);
    atomicAdd(&counters[HC_COUNTER_RAYS], sg_rays_traced);
    if hc.lookup == 0u {
        l = hc_demodulate(l, r.modulate);
    }
    if claimant {
        // Running mean up to max_samples, then an exponential average (temporal filtering).
        let old = cell_radiance[r.slot];
        let n = min(old.w + 1.0, hc.max_samples);
        cell_radiance[r.slot] = vec4f(old.rgb + (l - old.rgb) / n, n);
    } else {
        records[index].own_sample = l;
    }
}

@compute @workgroup_size(8, 8, 1)
fn hc_resolve(@builtin(global_invocation_id) id: vec3u) {
    if outside_image(id, frame.width, frame.height) {
        return;
    }
    let index = id.y * frame.width + id.x;
    let r = records[index];
    var c = r.direct;
    if (r.flags & HC_NEEDS_SAMPLE) != 0u {
        if r.slot != HC_NONE {
            c += r.modulate * cell_radiance[r.slot].rgb;
        } else {
            c += r.modulate * r.own_sample;
        }
    }
    colour_out[index] = vec4f(c, 1.0);
}
