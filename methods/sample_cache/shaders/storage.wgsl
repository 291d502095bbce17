// Stable sample cache (Philippi, Jensen & Frisvad 2025): storage, packing and the per-frame
// parameters. Its bindings (@group(2)) are generated from OWN_GROUP in src/lib.rs.
//
// Layout. N slots per pixel, "layered": slot s of pixel p lives at s * pixels + p (the paper's
// array of textures, one per slot index). A slot is 32 bytes: the first hit packed into a vec4u
// plus the shading cache (accumulated radiance, sample count c_s) in a vec4f.
// Hit packing (fixes listing 1, which ORs 8-bit material fields over 32-bit barycentrics): plain
// vec4u = (instance, primitive, bits(b1), bits(b2)) with full f32 barycentrics; the material is
// the instance's (sg_instance(i).material), so no material bits are stored at all.
// A background sample (its primary ray left the scene) is (NO_HIT, bits(dir.x, dir.y, dir.z)).
// Mask: one u32 per pixel, occupancy o_s in bits 0..N-1 and visibility v_s in bits N..2N-1
// (N <= 16), bits 2N..31 always zero.

import package::scene_geometry::{Hit, NO_HIT, SurfacePoint, surface_point};
import package::sample_cache_bindings::{ssc};

const SSC_MAX_SLOTS: u32 = 16u;
// Per pixel: reserved mask, farthest visible depth, retrace results, closest visible depth and
// its Δn (closest_main).
const SSC_ATOMICS: u32 = 5u;
// Depth of a background sample in the slope test (finite: the test multiplies it).
const SSC_BACKGROUND_DEPTH: f32 = 1.0e30;
// Closest depth of a pixel with no visible sample: never the closest of a neighbourhood.
const SSC_NO_DEPTH: f32 = 3.0e38;

// Words of `ssc_work` (header), then the shade list from SSC_LIST.
const SSC_SHADE_COUNT: u32 = 0u;
const SSC_RAYS: u32 = 1u;
const SSC_NEW: u32 = 2u;
const SSC_PURGED: u32 = 3u;
const SSC_REPROJECTED: u32 = 4u;
const SSC_DROPPED: u32 = 5u;
const SSC_WMIN_ACC: u32 = 6u;   // importance bounds seen this frame (float bits)
const SSC_WMAX_ACC: u32 = 7u;
const SSC_WMIN: u32 = 8u;       // bounds of the histogram buckets this frame (last frame's)
const SSC_WMAX: u32 = 9u;
const SSC_THRESHOLD: u32 = 10u; // bucket crossing the budget
const SSC_COIN: u32 = 11u;      // dispatch probability in that bucket (float bits)
const SSC_VISIBLE: u32 = 12u;
const SSC_OCCUPIED: u32 = 13u;
const SSC_BASE: u32 = 14u;
const SSC_FLAGGED: u32 = 15u;
const SSC_HISTOGRAM: u32 = 16u;
const SSC_AUDIT: u32 = 32u;         // visible samples found occluded by audit_main
const SSC_RETRACE_COUNT: u32 = 33u; // entries of the retrace list (shares SSC_LIST with the shade list)
const SSC_ALL_RAYS: u32 = 34u;      // every ray of the frame: retraces, new samples, shading paths
const SSC_RETRACE_ARGS: u32 = 35u;  // 3 words: indirect dispatch of retrace_list_main
const SSC_SHADE_ARGS: u32 = 38u;    // 3 words: indirect dispatch of shade_main
const SSC_LIST: u32 = 48u;

// The list passes (retrace_list_main, shade_main) run one thread per list entry in 1-D workgroups
// over an x·y grid of them (SampleCache::list_dispatch on the CPU, list_dispatch.wgsl on the GPU).
const SSC_LIST_WORKGROUP: u32 = 64u;
// WebGPU's guaranteed minimum of max_compute_workgroups_per_dimension: every adapter takes it.
const SSC_MAX_GROUPS_X: u32 = 65535u;

const SSC_FLAG_BASE: u32 = 1u;
const SSC_FLAG_SLOPE: u32 = 2u;
const SSC_FLAG_HOLE: u32 = 4u;

// The list entry of a thread of a list pass (global id, workgroups of the dispatch).
fn ssc_list_index(id: vec3u, groups: vec3u) -> u32 {
    return id.y * groups.x * SSC_LIST_WORKGROUP + id.x;
}

fn ssc_pixels() -> u32 {
    return ssc.width * ssc.height;
}

fn ssc_full() -> u32 {
    return (1u << ssc.slots) - 1u;
}

// Slots of a mask that are visible (visibility bits n..2n) and occupied (bits 0..n).
fn ssc_visible_slots(mask: u32) -> u32 {
    return (mask >> ssc.slots) & mask & ssc_full();
}

fn ssc_is_background(hit: vec4u) -> bool {
    return hit.x == NO_HIT;
}

fn ssc_pack_hit(h: Hit) -> vec4u {
    return vec4u(h.instance, h.primitive, bitcast<u32>(h.barycentrics.x), bitcast<u32>(h.barycentrics.y));
}

fn ssc_pack_background(dir: vec3f) -> vec4u {
    return vec4u(NO_HIT, bitcast<vec3u>(dir));
}

fn ssc_background_dir(hit: vec4u) -> vec3f {
    return bitcast<vec3f>(hit.yzw);
}

// The cached surface sample through the *current* instance transforms.
fn ssc_surface(hit: vec4u) -> SurfacePoint {
    return surface_point(ssc_hit(hit), vec3f(0.0), vec3f(0.0, 0.0, 1.0));
}

// A packed surface hit as the geometry's Hit (t unknown: 0).
fn ssc_hit(hit: vec4u) -> Hit {
    return Hit(0.0, hit.x, hit.y, bitcast<vec2f>(hit.zw));
}

// Strict lexicographic order on packed hits: the canonical slot order of a pixel.
fn ssc_less(a: vec4u, b: vec4u) -> bool {
    if a.x != b.x { return a.x < b.x; }
    if a.y != b.y { return a.y < b.y; }
    if a.z != b.z { return a.z < b.z; }
    return a.w < b.w;
}
