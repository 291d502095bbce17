// Hashed radiance cache with variance-trading termination (variance-trading-termination.txt):
// the passes of one frame. The voxel keys are the hash cache's (hash_key.wgsl, through its `hc`
// uniform, binding 0 of this pass's @group(2) too); the decision is decision.wgsl.
//
//   tc_propagate  per stored vertex (4 per record): K one-segment samples at the vertex (NEE +
//                 one BSDF sample ending in the cache at its hit) -> the vertex's mean, mean of
//                 squares and U-statistic over pairs; the first sample's hit is a candidate
//                 vertex for its own record (exploration)
//   tc_fold       per record: folds its vertices' estimates into the record's three moments
//   tc_trace      per pixel: the path with the termination decision at every vertex; primary
//                 vertices are candidates with probability store_probability (one tracer of a
//                 shared cache offers them, tc.offers)
//   tc_insert_*   per insertion request (a candidate whose key had no slot): rounds of claim
//                 (atomicMin of the candidate index on the first empty slot of its probe window)
//                 and win (the lowest claimant writes its key there), then a settle pass
//   tc_store      per record: the winning candidate (lowest permuted index: deterministic, one
//                 per record and frame) becomes one of the record's 4 stored vertices
//
// A slot is 4 u32 in `slots`: checksum (0 = empty), claim (permuted candidate index), vertices
// stored so far, insertion claim (candidate index). `records` holds the records' moments, then
// the per-vertex estimates of this frame; `vertices` the stored vertices, then the candidates
// (pixels, then propagation). `inserts` holds the insertion passes' indirect dispatch
// (workgroups, 1, 1), the request count, then 4 words per request (candidate, home, checksum,
// state). Records are never evicted (static scenes, the cache in equilibrium as in the paper's
// §6).
//
// Every result is independent of the order invocations run in: sums are per invocation or
// integer atomics, and every contended choice (a record's stored vertex, a key's slot) is an
// atomicMin over candidate indices.

import package::scene_bindings::{frame};
import package::scene_tables::{material};
import package::scene_geometry::{NO_HIT, sg_rays_traced, surface_point, trace_closest};
import package::pt_sampling::{luminance, rng_next, rng_next2, rng_seed};
import package::pt_bsdf::{bsdf_sample, make_bsdf};
import package::pt_lights::{FAR};
import package::pt_scene::{base_color_at, camera_ray_direction, escaped_radiance, offset_origin, orient};
import package::pt_integrator::{emitted_radiance, next_event, path_radiance};
import package::taa::primary::{primary_attributes};
import package::termination_types::{TcRecord, TcVertex};
import package::termination_bindings::{colour_out, counters, inserts, path_length, primary_out, records, slots, tc, vertices};
import package::hash_cache_bindings::{hc};
import package::hash_cache::hash_key::{HC_EMPTY, HC_NONE, VoxelKey, hc_key, hc_level};
import package::termination::decision::{TC_PATH_TRACING, TcLocalStats, TcPathState, TcRule, tc_arrive_area_spread, tc_decide, tc_threshold};
import package::kernel::{outside_image};

const TC_COUNTER_VERTICES: u32 = 0u;   // path vertices of the tracer's paths, x TC_LENGTH_SCALE
// Path length is counted in 1/256 vertex: the vertex after a blend counts alpha (the paper's
// path length "accounts for variance interpolation", §6).
const TC_LENGTH_SCALE: f32 = 256.0;
const TC_COUNTER_TRACE_RAYS: u32 = 1u;
const TC_COUNTER_PROPAGATE_RAYS: u32 = 2u;
const TC_COUNTER_INSERTED: u32 = 3u;
const TC_COUNTER_FAILED: u32 = 4u;
const TC_COUNTER_STORED: u32 = 5u;
const TC_COUNTER_UNKNOWN: u32 = 6u;    // decisions at a vertex without a filled record
const TC_COUNTER_PROPAGATED: u32 = 7u; // stored vertices propagated
const TC_COUNTER_FILLED: u32 = 9u;     // records holding moments after the fold
const TC_COUNTER_INCOMPLETE: u32 = 8u; // propagated vertices with a sample that hit no filled record

fn tc_rule() -> TcRule {
    return TcRule(tc.rule_kind, tc.relative, tc.param, tc.margin, tc.bias_clamp, tc.survival);
}

// The voxel of a point (level of detail from its camera distance), jittered for stochastic
// interpolation between neighbouring records [Binder et al. 2019].
fn tc_key(p: vec3f, n: vec3f, jitter: vec2f) -> VoxelKey {
    let to_point = p - frame.camera.position;
    let distance = max(length(to_point), 1.0e-20);
    return hc_key(p, n, hc_level(distance, dot(n, to_point) / distance), jitter);
}

// The slot of `key`, or HC_NONE. No eviction: probing may stop at the first empty slot.
fn tc_find(key: VoxelKey) -> u32 {
    for (var i = 0u; i < hc.probe_limit; i++) {
        let s = (key.home + i) % hc.capacity;
        let c = atomicLoad(&slots[4u * s]);
        if c == key.checksum {
            return s;
        }
        if c == HC_EMPTY {
            return HC_NONE;
        }
    }
    return HC_NONE;
}

// Insertion requests (`inserts`): header words, then TC_REQUEST_WORDS per request.
const TC_INSERT_GROUPS: u32 = 0u;       // workgroups of the insertion passes (indirect x; y = z = 1)
const TC_INSERT_COUNT: u32 = 3u;
const TC_INSERT_HEADER: u32 = 4u;
const TC_REQUEST_WORDS: u32 = 4u;       // candidate, home, checksum, state
const TC_INSERT_WORKGROUP: u32 = 256u;  // INSERT_WORKGROUP in cache.rs
// A request's state: its probe index while pending, with TC_CLAIMED while it claims that slot;
// TC_SETTLED once it has offered its vertex or failed.
const TC_CLAIMED: u32 = 0x80000000u;
const TC_SETTLED: u32 = 0xffffffffu;

// Offers candidate `candidate` (its vertex already written) to `slot`'s record.
fn tc_claim_vertex(slot: u32, candidate: u32) {
    atomicMin(&slots[4u * slot + 1u], candidate ^ tc.candidate_mask);
}

// Offers the vertex hit by the ray (origin, dir) to `slot`; `candidate` indexes the candidates.
fn tc_offer(slot: u32, candidate: u32, origin: vec3f, dir: vec3f) {
    vertices[4u * hc.capacity + candidate] = TcVertex(origin, 0.0, dir, 0.0);
    tc_claim_vertex(slot, candidate);
}

// Offers the vertex to the record of `key`, which has no slot yet: a request that the insertion
// passes settle. Inserting in place (a compare-exchange walk) would give a contended slot to
// whichever key gets there first, and a slot's index seeds its propagation: results would depend
// on the order invocations run in.
fn tc_request(key: VoxelKey, candidate: u32, origin: vec3f, dir: vec3f) {
    vertices[4u * hc.capacity + candidate] = TcVertex(origin, 0.0, dir, 0.0);
    let at = atomicAdd(&inserts[TC_INSERT_COUNT], 1u);
    if at % TC_INSERT_WORKGROUP == 0u {
        atomicAdd(&inserts[TC_INSERT_GROUPS], 1u);
    }
    let w = TC_INSERT_HEADER + TC_REQUEST_WORDS * at;
    atomicStore(&inserts[w], candidate);
    atomicStore(&inserts[w + 1u], key.home);
    atomicStore(&inserts[w + 2u], key.checksum);
    atomicStore(&inserts[w + 3u], 0u);
}

// The first word of invocation `id`'s request, or HC_NONE past the list's end. Nothing depends
// on a request's place in the list (claims compare candidate indices).
fn tc_request_word(id: vec3u) -> u32 {
    if id.x >= atomicLoad(&inserts[TC_INSERT_COUNT]) {
        return HC_NONE;
    }
    return TC_INSERT_HEADER + TC_REQUEST_WORDS * id.x;
}

// A pending request's walk from its probe index over the slots as the pass found them (no
// checksum is written during a claim pass): its own key (offer there, settled), the first empty
// slot (claim it: atomicMin of the candidate index; with `claim` false, fail instead), or the
// end of the probe window (fail).
fn tc_insert_walk(w: u32, claim: bool) {
    let state = atomicLoad(&inserts[w + 3u]);
    if state == TC_SETTLED {
        return;
    }
    let candidate = atomicLoad(&inserts[w]);
    let home = atomicLoad(&inserts[w + 1u]);
    let checksum = atomicLoad(&inserts[w + 2u]);
    for (var i = state & ~TC_CLAIMED; i < hc.probe_limit; i++) {
        let s = (home + i) % hc.capacity;
        let c = atomicLoad(&slots[4u * s]);
        if c == checksum {
            tc_claim_vertex(s, candidate);
            atomicStore(&inserts[w + 3u], TC_SETTLED);
            return;
        }
        if c == HC_EMPTY {
            if !claim {
                break;
            }
            atomicMin(&slots[4u * s + 3u], candidate);
            atomicStore(&inserts[w + 3u], i | TC_CLAIMED);
            return;
        }
    }
    atomicAdd(&counters[TC_COUNTER_FAILED], 1u);
    atomicStore(&inserts[w + 3u], TC_SETTLED);
}

@compute @workgroup_size(256, 1, 1)
fn tc_insert_claim(@builtin(global_invocation_id) id: vec3u) {
    let w = tc_request_word(id);
    if w != HC_NONE {
        tc_insert_walk(w, true);
    }
}

// The lowest claimant of each claimed slot writes its key there and offers its vertex; the
// others stay at that probe index: the next claim pass finds their own key there (the same key
// won) or walks on.
@compute @workgroup_size(256, 1, 1)
fn tc_insert_win(@builtin(global_invocation_id) id: vec3u) {
    let w = tc_request_word(id);
    if w == HC_NONE {
        return;
    }
    let state = atomicLoad(&inserts[w + 3u]);
    if state == TC_SETTLED || (state & TC_CLAIMED) == 0u {
        return;
    }
    let i = state & ~TC_CLAIMED;
    let candidate = atomicLoad(&inserts[w]);
    let s = (atomicLoad(&inserts[w + 1u]) + i) % hc.capacity;
    if atomicLoad(&slots[4u * s + 3u]) != candidate {
        atomicStore(&inserts[w + 3u], i);
        return;
    }
    atomicStore(&slots[4u * s], atomicLoad(&inserts[w + 2u]));
    atomicAdd(&counters[TC_COUNTER_INSERTED], 1u);
    tc_claim_vertex(s, candidate);
    atomicStore(&inserts[w + 3u], TC_SETTLED);
}

// After the last round: a request that lost its last claim finds its key (the same key won) or
// fails.
@compute @workgroup_size(256, 1, 1)
fn tc_insert_settle(@builtin(global_invocation_id) id: vec3u) {
    let w = tc_request_word(id);
    if w != HC_NONE {
        tc_insert_walk(w, false);
    }
}

// mean^2 - Var(mean) from the running mean, the mean of squared vertex means and the weights'
// sum of squares (moments.rs mean_squared_unbiased): the squared mean alone is high by Var(mean).
fn tc_mean_squared(mean: f32, mean_sq: f32, weight2: f32) -> f32 {
    if weight2 >= 1.0 {
        return mean * mean;
    }
    return mean * mean - (mean_sq - mean * mean) * weight2 / (1.0 - weight2);
}

// The record's statistics for the decision (luminance).
fn tc_stats(r: TcRecord) -> TcLocalStats {
    let mean = luminance(r.mean);
    let bias2 = max(r.marginal - tc_mean_squared(mean, r.mean_sq, r.weight2), 0.0);
    return TcLocalStats(mean, max(r.second - r.marginal, 0.0), r.continuation2, bias2, r.deferred_bias2);
}

// A filled record at the point (jittered lookup), or a record with vertices = 0.
fn tc_lookup(p: vec3f, n: vec3f, rng: ptr<function, u32>) -> TcRecord {
    let s = tc_find(tc_key(p, n, rng_next2(rng)));
    if s == HC_NONE {
        return TcRecord(vec3f(0.0), 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0);
    }
    return records[s];
}

@compute @workgroup_size(64, 1, 1)
fn tc_propagate(@builtin(global_invocation_id) id: vec3u) {
    let slot = id.x / 4u;
    if slot >= hc.capacity {
        return;
    }
    let estimate = hc.capacity + id.x;
    records[estimate].vertices = 0.0;
    let stored = atomicLoad(&slots[4u * slot + 2u]);
    if atomicLoad(&slots[4u * slot]) == HC_EMPTY || id.x % 4u >= min(stored, 4u) {
        return;
    }
    let v = vertices[id.x];
    let hit = trace_closest(v.origin, v.dir, FAR);
    if hit.instance == NO_HIT {
        atomicAdd(&counters[TC_COUNTER_PROPAGATE_RAYS], sg_rays_traced);
        return;
    }
    var rng = rng_seed(vec2u(frame.seed_lo, frame.seed_hi), frame.frame, id.x, 0x70726f70u);
    let sp = surface_point(hit, v.origin, v.dir);
    let m = material(sp.material);
    let wo = -v.dir;
    let sh = orient(sp, wo);
    let bsdf = make_bsdf(base_color_at(m, sp.uv), m.metallic, m.roughness, m.specular);
    var sum = vec3f(0.0);
    var sum_y = 0.0;
    var sum_y2 = 0.0;
    var sum_b2 = 0.0; // the continuation's squares: Y = NEE + B, roulette keeps only B
    var deferred = 0.0;
    // A sample whose hit has no filled record yet reads 0, which darkens the record: such an
    // estimate only starts an empty record (the iteration's bootstrap), never updates a filled one
    // (tc.incomplete 0); or the sample goes on by path tracing from that hit, which keeps the
    // estimate unbiased and complete (1); or it counts as read, the empty record's 0 included, as
    // the paper's propagation reads the cache at the hit (2).
    var complete = true;
    var unknown_hit = false;
    for (var k = 0u; k < tc.samples_per_vertex; k++) {
        let nee = next_event(sp.position, sh, bsdf, wo, &rng);
        var y = nee;
        let bs = bsdf_sample(bsdf, sh.ns, wo, rng_next(&rng), rng_next2(&rng));
        if bs.valid && dot(bs.wi, sh.ng) > 0.0 {
            let w = bs.f * (dot(sh.ns, bs.wi) / bs.pdf);
            let o2 = offset_origin(sp.position, sh.ng, bs.wi);
            let hit2 = trace_closest(o2, bs.wi, FAR);
            if hit2.instance == NO_HIT {
                y += w * escaped_radiance(bs.wi, bs.pdf);
            } else {
                let sp2 = surface_point(hit2, o2, bs.wi);
                let sh2 = orient(sp2, -bs.wi);
                let key2 = tc_key(sp2.position, sh2.ns, rng_next2(&rng));
                let s2 = tc_find(key2);
                if s2 != HC_NONE && records[s2].vertices > 0.0 {
                    y += w * emitted_radiance(sp2, material(sp2.material), bs.wi, hit2.t, bs.pdf);
                    let r2 = records[s2];
                    y += w * r2.mean;
                    let lw = luminance(w);
                    deferred += lw * lw * tc_stats(r2).bias2;
                } else {
                    unknown_hit = true;
                    if tc.incomplete == 1u {
                        // The hit's emission and the path after it, to the frame's max depth.
                        y += w * path_radiance(o2, bs.wi, bs.pdf, 1u, &rng);
                    } else {
                        y += w * emitted_radiance(sp2, material(sp2.material), bs.wi, hit2.t, bs.pdf);
                        complete = complete && tc.incomplete == 2u;
                    }
                }
                if k == 0u {
                    // Exploration: the hit may become a stored vertex of its record.
                    if s2 != HC_NONE {
                        tc_offer(s2, tc.pixels + id.x, o2, bs.wi);
                    } else {
                        tc_request(key2, tc.pixels + id.x, o2, bs.wi);
                    }
                }
            }
        }
        sum += y;
        let ly = luminance(y);
        sum_y += ly;
        sum_y2 += ly * ly;
        let lb = luminance(y - nee);
        sum_b2 += lb * lb;
    }
    atomicAdd(&counters[TC_COUNTER_PROPAGATE_RAYS], sg_rays_traced);
    atomicAdd(&counters[select(TC_COUNTER_PROPAGATED, TC_COUNTER_INCOMPLETE, unknown_hit)], 1u);
    let n = f32(tc.samples_per_vertex);
    // Mean, mean of squares, and the U-statistic over all pairs ((sum)^2 - sum of squares) / (K(K-1)).
    let mean_y = sum_y / n;
    records[estimate] = TcRecord(sum / n, 1.0, sum_y2 / n, (sum_y * sum_y - sum_y2) / (n * (n - 1.0)), deferred / n, sum_b2 / n, mean_y * mean_y, 1.0, select(0.0, 1.0, complete), 0.0);
}

@compute @workgroup_size(64, 1, 1)
fn tc_fold(@builtin(global_invocation_id) id: vec3u) {
    let slot = id.x;
    if slot >= hc.capacity || atomicLoad(&slots[4u * slot]) == HC_EMPTY {
        return;
    }
    var r = records[slot];
    for (var v = 0u; v < 4u; v++) {
        let e = records[hc.capacity + 4u * slot + v];
        if e.vertices > 0.0 && (e.complete > 0.0 || r.vertices == 0.0) {
            // Running mean over vertices, exponential once max_vertices is reached.
            let n = min(r.vertices + 1.0, tc.max_vertices);
            let a = 1.0 / n;
            r.mean += (e.mean - r.mean) * a;
            r.second += (e.second - r.second) * a;
            r.marginal += (e.marginal - r.marginal) * a;
            r.deferred_bias2 += (e.deferred_bias2 - r.deferred_bias2) * a;
            r.continuation2 += (e.continuation2 - r.continuation2) * a;
            r.mean_sq += (e.mean_sq - r.mean_sq) * a;
            // Sum of the squared weights of the vertices in the running mean (moments.rs).
            r.weight2 = (1.0 - a) * (1.0 - a) * r.weight2 + a * a;
            r.vertices = n;
        }
    }
    records[slot] = r;
    if r.vertices > 0.0 {
        atomicAdd(&counters[TC_COUNTER_FILLED], 1u);
    }
}

@compute @workgroup_size(8, 8, 1)
fn tc_trace(@builtin(global_invocation_id) id: vec3u) {
    if outside_image(id, frame.width, frame.height) {
        return;
    }
    let index = id.y * frame.width + id.x;
    // The path tracer's camera ray and random stream (path_tracer.wgsl trace_path).
    var rng = rng_seed(vec2u(frame.seed_lo, frame.seed_hi), frame.frame, index, frame.first_sample);
    let jitter = rng_next2(&rng);
    var origin = frame.camera.position;
    var dir = camera_ray_direction(frame.camera, vec2f(id.xy) + jitter);
    // Lookups and storing draw from their own stream: path tracing keeps the tracer's numbers.
    var crng = rng_seed(vec2u(frame.seed_lo, frame.seed_hi), frame.frame, index, 0x63616368u);
    let rule = tc_rule();
    var state = TcPathState(1.0, 0.0, 0.0, 0.0, 0.0, 0u);
    var throughput = vec3f(1.0);
    var radiance = vec3f(0.0);
    var prev_bsdf_pdf = 0.0;
    var path_vertices = 0.0;
    var blend_alpha = 1.0;
    var blended = false;
    for (var depth = 0u; depth <= frame.max_depth; depth++) {
        let hit = trace_closest(origin, dir, FAR);
        if depth == 0u {
            primary_out[index] = primary_attributes(hit, origin, dir);
        }
        if hit.instance == NO_HIT {
            radiance += throughput * escaped_radiance(dir, prev_bsdf_pdf);
            break;
        }
        let sp = surface_point(hit, origin, dir);
        let m = material(sp.material);
        let wo = -dir;
        let sh = orient(sp, wo);
        path_vertices += blend_alpha;
        radiance += throughput * emitted_radiance(sp, m, dir, hit.t, prev_bsdf_pdf);
        if blended {
            // The blended segment (eq. 5) ends into the cache at its hit.
            radiance += throughput * tc_lookup(sp.position, sh.ns, &crng).mean;
            break;
        }
        if depth == frame.max_depth {
            break;
        }
        state.vertex = depth + 1u;
        tc_arrive_area_spread(&state, hit.t * hit.t, prev_bsdf_pdf, dot(sh.ns, wo));
        var alpha = 1.0;
        var cached = vec3f(0.0);
        if rule.kind != TC_PATH_TRACING {
            let r = tc_lookup(sp.position, sh.ns, &crng);
            let stats = tc_stats(r);
            if depth == 0u {
                state.threshold = tc_threshold(rule, stats.radiance, r.vertices > 0.0);
            }
            if r.vertices > 0.0 {
                let lt = luminance(throughput);
                state.throughput2 = lt * lt;
                alpha = tc_decide(rule, &state, stats);
                cached = r.mean;
            } else {
                atomicAdd(&counters[TC_COUNTER_UNKNOWN], 1u);
            }
        }
        if depth == 0u && rng_next(&crng) < tc.store_probability {
            let key = tc_key(sp.position, sh.ns, rng_next2(&crng));
            // Every rule but path tracing offers the same vertex here (its random numbers so
            // far are the rule's lookup's): on a shared cache one tracer offers, the others only
            // draw the numbers.
            if tc.offers != 0u {
                let s = tc_find(key);
                if s != HC_NONE {
                    tc_offer(s, index, origin, dir);
                } else {
                    tc_request(key, index, origin, dir);
                }
            }
        }
        if alpha < 1.0 {
            radiance += throughput * (1.0 - alpha) * cached;
            if alpha <= 0.0 {
                break;
            }
            throughput *= alpha;
            blended = true;
            blend_alpha = alpha;
        }
        let bsdf = make_bsdf(base_color_at(m, sp.uv), m.metallic, m.roughness, m.specular);
        radiance += throughput * next_event(sp.position, sh, bsdf, wo, &rng);
        let bs = bsdf_sample(bsdf, sh.ns, wo, rng_next(&rng), rng_next2(&rng));
        if !bs.valid || dot(bs.wi, sh.ng) <= 0.0 {
            break;
        }
        throughput *= bs.f * (dot(sh.ns, bs.wi) / bs.pdf);
        prev_bsdf_pdf = bs.pdf;
        if tc.survival < 1.0 {
            if rng_next(&crng) >= tc.survival {
                break;
            }
            throughput /= tc.survival;
        }
        origin = offset_origin(sp.position, sh.ng, bs.wi);
        dir = bs.wi;
    }
    colour_out[index] = vec4f(radiance, 1.0);
    path_length[index] = path_vertices;
    atomicAdd(&counters[TC_COUNTER_VERTICES], u32(round(path_vertices * TC_LENGTH_SCALE)));
    atomicAdd(&counters[TC_COUNTER_TRACE_RAYS], sg_rays_traced);
}

@compute @workgroup_size(64, 1, 1)
fn tc_store(@builtin(global_invocation_id) id: vec3u) {
    let slot = id.x;
    if slot >= hc.capacity {
        return;
    }
    let claim = atomicLoad(&slots[4u * slot + 1u]);
    atomicStore(&slots[4u * slot + 1u], HC_NONE);
    atomicStore(&slots[4u * slot + 3u], HC_NONE);
    if claim == HC_NONE {
        return;
    }
    let n = atomicLoad(&slots[4u * slot + 2u]);
    vertices[4u * slot + n % 4u] = vertices[4u * hc.capacity + (claim ^ tc.candidate_mask)];
    atomicStore(&slots[4u * slot + 2u], n + 1u);
    atomicAdd(&counters[TC_COUNTER_STORED], 1u);
}
