// Cache-terminated paths (NIRC): camera paths end in a query of the incident radiance cache,
// a sparse seeded subset of them is extended into Monte Carlo training targets, and a resolve
// pass turns the cache's answers into the image. Built on the pass library's modules; the scene
// is @group(0), the geometry @group(1), these buffers @group(2) (integrator.rs).
//
// Estimator. A camera path is traced by pt_integrator.wgsl's `trace_path_prefix` (emission,
// NEE with MIS, BSDF sampling, Russian roulette) up to the termination vertex x_k (k =
// `termination_vertex`, 1 = the primary hit). There:
//   L(x_k -> wo) = Le(x_k) [MIS-weighted as the path tracer]
//                + NEE of every analytic light and of one emissive triangle, without MIS
//                + f(wo, w) cos / pdf(w) * Lc(x_k, w),   w ~ BSDF
// where Lc(x, w) is the radiance arriving at x along w WITHOUT light that comes straight from an
// emitter: no analytic light, and no emission of the surface the ray hits first. The
// environment seen along w stays in Lc (it is a smooth function of w alone, which the cache
// learns easily); everything scattered at least once stays in Lc.
// Direct light is split off for two reasons. A BSDF-sampled direction (almost) never hits a
// point, spot or 0.27°-wide sun, so the cache could not learn them. And small emissive
// triangles (a corridor's ceiling lamps, a Cornell box's light) make the incident radiance a
// needle in direction space that a small hash-grid MLP blurs away: the lights then reached the
// primary hits only through that blur, and the image came out dark (measured: docs/lab/nirc-lavapipe.md).
// Each light path reaches x_k's estimate through exactly one strategy, so no MIS weight is
// needed at x_k.
// The cache learns Lc from `cache_target`, an unbiased one-sample estimate: the ray (x_k, w),
// no emission at its hit, then NEE + MIS at the hit and path_radiance from there up to the
// frame's max depth. Replacing the cache by cache_target (the oracle) gives an estimator with
// the same mean as the path tracer's (test: tests/integrator.rs).

import package::scene_bindings::{frame};
import package::scene_tables::{material};
import package::scene_geometry::{NO_HIT, sg_rays_traced, surface_point, trace_closest};
import package::pt_sampling::{max_component, rng_next, rng_next2, rng_seed};
import package::pt_bsdf::{bsdf_sample, make_bsdf};
import package::pt_lights::{FAR};
import package::pt_scene::{base_color_at, camera_ray_direction, offset_origin, orient, primary_motion};
import package::pt_integrator::{next_event, next_event_analytic, next_event_emitter, path_radiance, trace_path_prefix};
import package::nirc::cache_path_types::{CacheQuery, TrainingRecord};
import package::nirc::query_meta::{QueryMeta};
import package::nirc::cache_path_bindings::{answers, image, motion, params, queries, query_meta, ray_counters, records};
import package::kernel::{outside_image};

// CacheParams, CacheQuery and TrainingRecord (position.w: 1 = valid) are declared once for Rust
// and WGSL (src/integrator.rs, src/records.rs).

// Stream of training-path random numbers: disjoint from the camera samples' (small indices).
const TRAIN_SAMPLE_STREAM: u32 = 0x80000001u;
const TRAIN_PICK_STREAM: u32 = 0x80000002u;
// Candidates a training record tries before giving up (a sky pixel has no query).
const PICK_TRIES: u32 = 16u;

// One-sample estimate of Lc(x, dir) for the ray (origin, dir) at path depth `depth`.
fn cache_target(origin: vec3f, dir: vec3f, depth: u32, rng: ptr<function, u32>) -> vec3f {
    let hit = trace_closest(origin, dir, FAR);
    if hit.instance == NO_HIT {
        // The environment only: the analytic lights' disks are NEE's.
        return frame.environment;
    }
    let sp = surface_point(hit, origin, dir);
    let m = material(sp.material);
    let wo = -dir;
    let sh = orient(sp, wo);
    // The hit's own emission is direct light: NEE's at x_k, not the cache's.
    var l = vec3f(0.0);
    if depth >= frame.max_depth {
        return l;
    }
    let bsdf = make_bsdf(base_color_at(m, sp.uv), m.metallic, m.roughness, m.specular);
    let p = sp.position;
    l += next_event(p, sh, bsdf, wo, rng);
    let bs = bsdf_sample(bsdf, sh.ns, wo, rng_next(rng), rng_next2(rng));
    if !bs.valid || dot(bs.wi, sh.ng) <= 0.0 {
        return l;
    }
    var throughput = bs.f * (dot(sh.ns, bs.wi) / bs.pdf);
    if depth + 1u >= frame.rr_start_depth {
        let survive = min(max_component(throughput), 0.95);
        if rng_next(rng) >= survive {
            return l;
        }
        throughput /= survive;
    }
    return l + throughput * path_radiance(offset_origin(p, sh.ng, bs.wi), bs.wi, bs.pdf, depth + 1u, rng);
}

// One camera path up to its termination vertex; writes query q's position, direction, weight.
fn trace_query(pixel: vec2u, sample_index: u32, q: u32) {
    var rng = rng_seed(vec2u(frame.seed_lo, frame.seed_hi), frame.frame, pixel.y * frame.width + pixel.x, sample_index);
    let jitter = rng_next2(&rng);
    let dir = camera_ray_direction(frame.camera, vec2f(pixel) + jitter);
    let path = trace_path_prefix(frame.camera.position, dir, 0.0, 0u, params.termination_vertex - 1u, &rng);
    var radiance = path.radiance;
    var result: QueryMeta;
    result.weight = vec4f(0.0);
    result.origin = vec4f(0.0);
    var query: CacheQuery;
    query.position = vec4f(0.0);
    query.direction = vec4f(0.0, 0.0, 1.0, 0.0);
    if path.stopped {
        // Termination vertex: direct light by NEE, everything else from the cache.
        let p = path.p;
        let sh = path.sh;
        radiance += path.throughput * (next_event_analytic(p, sh, path.bsdf, path.wo, &rng, false)
            + next_event_emitter(p, sh, path.bsdf, path.wo, &rng, false));
        let bs = bsdf_sample(path.bsdf, sh.ns, path.wo, rng_next(&rng), rng_next2(&rng));
        if bs.valid && dot(bs.wi, sh.ng) > 0.0 {
            result.weight = vec4f(path.throughput * bs.f * (dot(sh.ns, bs.wi) / bs.pdf), 1.0);
            result.origin = vec4f(offset_origin(p, sh.ng, bs.wi), f32(path.depth + 1u));
            query.position = vec4f(p, 0.0);
            query.direction = vec4f(bs.wi, 0.0);
        }
    }
    result.prefix = vec4f(radiance, 0.0);
    query_meta[q] = result;
    queries[q] = query;
}

// Per pixel: `spp` camera paths, queries at pixel * spp + s.
@compute @workgroup_size(8, 8, 1)
fn queries_main(@builtin(global_invocation_id) id: vec3u) {
    if outside_image(id, frame.width, frame.height) {
        return;
    }
    let pixel = id.y * frame.width + id.x;
    for (var s = 0u; s < params.spp; s++) {
        trace_query(id.xy, s, pixel * params.spp + s);
    }
    let origin = frame.camera.position;
    let dir = camera_ray_direction(frame.camera, vec2f(id.xy) + 0.5);
    let hit = trace_closest(origin, dir, FAR);
    var hit_point = origin;
    if hit.instance != NO_HIT {
        hit_point = surface_point(hit, origin, dir).position;
    }
    motion[pixel] = primary_motion(hit, origin, dir, hit_point);
    atomicAdd(&ray_counters[0], sg_rays_traced);
}

fn target_of(q: u32, rng: ptr<function, u32>) -> vec3f {
    let m = query_meta[q];
    return cache_target(m.origin.xyz, queries[q].direction.xyz, u32(m.origin.w), rng);
}

// Per training record slot: a seeded random query of this frame that exists, and the Monte
// Carlo target of its incident radiance; written as a candidate (compacted below).
@compute @workgroup_size(64, 1, 1)
fn targets_main(@builtin(global_invocation_id) id: vec3u) {
    let i = id.x;
    if i >= params.record_count {
        return;
    }
    var pick = rng_seed(vec2u(frame.seed_lo, frame.seed_hi), frame.frame, i, TRAIN_PICK_STREAM);
    var chosen = 0xffffffffu;
    for (var t = 0u; t < PICK_TRIES; t++) {
        let c = min(u32(rng_next(&pick) * f32(params.query_count)), params.query_count - 1u);
        if query_meta[c].weight.w > 0.0 {
            chosen = c;
            break;
        }
    }
    var r: TrainingRecord;
    r.position = vec4f(0.0);
    r.direction = vec4f(0.0, 0.0, 1.0, 0.0);
    r.target_rgb = vec4f(0.0);
    if chosen != 0xffffffffu {
        var rng = rng_seed(vec2u(frame.seed_lo, frame.seed_hi), frame.frame, i, TRAIN_SAMPLE_STREAM);
        r.position = vec4f(queries[chosen].position.xyz, 1.0);
        r.direction = queries[chosen].direction;
        r.target_rgb = vec4f(target_of(chosen, &rng), 0.0);
    }
    records[params.record_count + i] = r;
    atomicAdd(&ray_counters[1], sg_rays_traced);
}

// One thread: the valid candidates in slot order, then repeated cyclically to fill every slot
// (deterministic, no readback of the count). With no valid candidate at all (an empty view),
// the slots keep zero targets at the bounds' corner.
@compute @workgroup_size(1, 1, 1)
fn compact_main() {
    let n = params.record_count;
    var count = 0u;
    for (var i = 0u; i < n; i++) {
        let r = records[n + i];
        if r.position.w > 0.0 {
            records[count] = r;
            count++;
        }
    }
    for (var j = count; j < n; j++) {
        if count > 0u {
            records[j] = records[j % count];
        } else {
            records[j] = records[n + j];
        }
    }
}

// Test oracle: every query answered by its own Monte Carlo target (same mean as the exact Lc).
@compute @workgroup_size(64, 1, 1)
fn oracle_main(@builtin(global_invocation_id) id: vec3u) {
    let q = id.x;
    if q >= params.query_count {
        return;
    }
    var l = vec3f(0.0);
    if query_meta[q].weight.w > 0.0 {
        var rng = rng_seed(vec2u(frame.seed_lo, frame.seed_hi), frame.frame ^ 0x0c0ffeeu, q, TRAIN_SAMPLE_STREAM);
        l = target_of(q, &rng);
    }
    answers[q] = vec4f(l, 0.0);
}

// Per pixel: mean over samples of prefix + weight * answer; and in image[pixels + pixel] the
// mean σ (weight of the High-LR predictor) of the pixel's answered queries, w = their count.
@compute @workgroup_size(8, 8, 1)
fn resolve_main(@builtin(global_invocation_id) id: vec3u) {
    if outside_image(id, frame.width, frame.height) {
        return;
    }
    let pixel = id.y * frame.width + id.x;
    var sum = vec3f(0.0);
    var sigma = 0.0;
    var answered = 0.0;
    for (var s = 0u; s < params.spp; s++) {
        let q = pixel * params.spp + s;
        let m = query_meta[q];
        sum += m.prefix.xyz;
        if m.weight.w > 0.0 {
            let a = answers[q];
            sum += m.weight.xyz * a.xyz;
            sigma += a.w;
            answered += 1.0;
        }
    }
    image[pixel] = vec4f(sum / f32(params.spp), 1.0);
    image[frame.width * frame.height + pixel] = vec4f(sigma / max(answered, 1.0), 0.0, 0.0, answered);
}
