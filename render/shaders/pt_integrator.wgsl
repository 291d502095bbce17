// Path integrator shared by every pass that shades: next-event estimation with MIS, emission,
// and the path loop.

import package::scene_types::{GpuMaterial};
import package::scene_features::{HAS_ANALYTIC_LIGHTS, HAS_EMITTERS, HAS_ENVIRONMENT};
import package::scene_bindings::{frame};
import package::scene_tables::{material, light};
import package::scene_geometry::{NO_HIT, SurfacePoint, surface_point, trace_any, trace_closest};
import package::pt_sampling::{luminance, max_component, power_heuristic, rng_next, rng_next2, sample_uniform_sphere};
import package::pt_bsdf::{Bsdf, bsdf_eval, bsdf_pdf, bsdf_sample, make_bsdf};
import package::pt_lights::{FAR, emitter_pdf, sample_analytic_light, sample_emitter};
import package::pt_scene::{Shading, base_color_at, environment_pdf, escaped_radiance, offset_origin, orient};

// Next-event estimation at a surface point: every analytic light, one emissive triangle, the
// environment, each MIS-weighted (power heuristic) against the BSDF's pdf. The three parts are
// separate functions because a cache-terminated path (nirc) needs some of them without MIS;
// `mis` = false gives the plain light-sampling estimate. The random numbers drawn do not
// depend on `mis`. A kind of light the scene lacks is compiled out (scene_features.rs says why);
// its estimator draws no random numbers either way.
fn next_event(p: vec3f, sh: Shading, bsdf: Bsdf, wo: vec3f, rng: ptr<function, u32>) -> vec3f {
    return next_event_analytic(p, sh, bsdf, wo, rng, true)
        + next_event_emitter(p, sh, bsdf, wo, rng, true)
        + next_event_environment(p, sh, bsdf, wo, rng);
}

fn next_event_analytic(p: vec3f, sh: Shading, bsdf: Bsdf, wo: vec3f, rng: ptr<function, u32>, mis: bool) -> vec3f {
    var radiance = vec3f(0.0);
    if !HAS_ANALYTIC_LIGHTS {
        return radiance;
    }
    for (var i = 0u; i < frame.analytic_lights; i++) {
        let ls = sample_analytic_light(light(i), p, rng_next2(rng));
        if dot(ls.wi, sh.ng) <= 0.0 || max_component(ls.weight) <= 0.0 {
            continue;
        }
        let f = bsdf_eval(bsdf, sh.ns, wo, ls.wi);
        if max_component(f) <= 0.0 {
            continue;
        }
        let o = offset_origin(p, sh.ng, ls.wi);
        if trace_any(o, ls.wi, ls.dist * (1.0 - 1.0e-4)) {
            continue;
        }
        var w = 1.0;
        if mis && ls.pdf > 0.0 {
            w = power_heuristic(ls.pdf, bsdf_pdf(bsdf, sh.ns, wo, ls.wi));
        }
        radiance += f * dot(sh.ns, ls.wi) * ls.weight * w;
    }
    return radiance;
}

// One emissive triangle, chosen by power.
fn next_event_emitter(p: vec3f, sh: Shading, bsdf: Bsdf, wo: vec3f, rng: ptr<function, u32>, mis: bool) -> vec3f {
    let emitter_count = frame.emitters;
    if !HAS_EMITTERS || emitter_count == 0u {
        return vec3f(0.0);
    }
    let u_select = rng_next(rng);
    let ls = sample_emitter(frame.analytic_lights, emitter_count, p, u_select, rng_next2(rng));
    if ls.pdf <= 0.0 || dot(ls.wi, sh.ng) <= 0.0 {
        return vec3f(0.0);
    }
    let f = bsdf_eval(bsdf, sh.ns, wo, ls.wi);
    if max_component(f) <= 0.0 {
        return vec3f(0.0);
    }
    let o = offset_origin(p, sh.ng, ls.wi);
    if trace_any(o, ls.wi, ls.dist * (1.0 - 1.0e-3)) {
        return vec3f(0.0);
    }
    var w = 1.0;
    if mis {
        w = power_heuristic(ls.pdf, bsdf_pdf(bsdf, sh.ns, wo, ls.wi));
    }
    return f * dot(sh.ns, ls.wi) * ls.weight * w;
}

// The constant environment, sampled uniformly over the sphere, always MIS-weighted.
fn next_event_environment(p: vec3f, sh: Shading, bsdf: Bsdf, wo: vec3f, rng: ptr<function, u32>) -> vec3f {
    let env_pdf = environment_pdf();
    if !HAS_ENVIRONMENT || env_pdf <= 0.0 {
        return vec3f(0.0);
    }
    let wi = sample_uniform_sphere(rng_next2(rng));
    if dot(wi, sh.ng) <= 0.0 {
        return vec3f(0.0);
    }
    let f = bsdf_eval(bsdf, sh.ns, wo, wi);
    if max_component(f) <= 0.0 || trace_any(offset_origin(p, sh.ng, wi), wi, FAR) {
        return vec3f(0.0);
    }
    let w = power_heuristic(env_pdf, bsdf_pdf(bsdf, sh.ns, wo, wi));
    return f * dot(sh.ns, wi) * frame.environment * (w / env_pdf);
}

// Emitted radiance seen along a ray that hit `sp` at distance `dist`, MIS-weighted against the
// light-sampling pdf when the ray was BSDF-sampled (`prev_bsdf_pdf` > 0).
// Emitters are one-sided (front face by winding, as pbrt's area lights and glTF's emissive):
// a two-sided light a few millimetres under a ceiling traps light between its back face and
// the ceiling, an unbounded-variance source of fireflies.
fn emitted_radiance(sp: SurfacePoint, m: GpuMaterial, dir: vec3f, dist: f32, prev_bsdf_pdf: f32) -> vec3f {
    let le_lum = luminance(m.emission);
    let cos_light = -dot(sp.geometric_normal, dir);
    if le_lum <= 0.0 || cos_light <= 0.0 {
        return vec3f(0.0);
    }
    var w = 1.0;
    let emitter_weight = frame.emitter_weight;
    if prev_bsdf_pdf > 0.0 && emitter_weight > 0.0 {
        let light_pdf = emitter_pdf(le_lum, cos_light, dist, emitter_weight);
        w = power_heuristic(prev_bsdf_pdf, light_pdf);
    }
    return m.emission * w;
}

// A path traced up to a vertex where its caller takes over (a cache query, nirc), or to its end.
struct PathPrefix {
    radiance: vec3f,    // gathered up to the stop vertex, its own (MIS-weighted) emission included
    throughput: vec3f,  // of the path up to the stop vertex
    stopped: bool,      // true: the path reached a surface at `stop_depth` below the max depth
    p: vec3f,           // the stop vertex, its shading frame, BSDF and outgoing direction
    sh: Shading,
    bsdf: Bsdf,
    wo: vec3f,
    depth: u32,
}

// Never stop early: trace to the frame's max depth.
const NO_STOP: u32 = 0xffffffffu;

// Radiance carried back along a path that starts with the ray (origin, dir) at vertex `depth`
// (0 = camera ray), up to the frame's max depth. `prev_bsdf_pdf` is the pdf that chose `dir`
// (0 for a camera ray: no MIS on what it hits). Russian roulette from frame.rr_start_depth on.
fn path_radiance(origin: vec3f, dir: vec3f, prev_bsdf_pdf: f32, depth: u32, rng: ptr<function, u32>) -> vec3f {
    return trace_path_prefix(origin, dir, prev_bsdf_pdf, depth, NO_STOP, rng).radiance;
}

// The state a path carries from one vertex to the next, so that a kernel can advance paths one
// vertex at a time and start a new path in a lane whose path has ended while the other lanes go
// on (path regeneration, Novák, Havran & Dachsbacher 2010); trace_path_prefix runs one path.
struct PathState {
    origin: vec3f,
    dir: vec3f,
    throughput: vec3f,
    radiance: vec3f,
    prev_bsdf_pdf: f32,
    depth: u32,
    done: bool,
}

// A path starting with the ray (origin, dir) at vertex `depth`, as path_radiance's arguments.
fn path_start(origin: vec3f, dir: vec3f, prev_bsdf_pdf: f32, depth: u32) -> PathState {
    return PathState(origin, dir, vec3f(1.0), vec3f(0.0), prev_bsdf_pdf, depth, depth > frame.max_depth);
}

// One vertex of the path loop: the ray's hit, its emission, NEE and the next direction, with
// Russian roulette from frame.rr_start_depth on. Sets `done` when the path ends; at the surface
// vertex `stop_depth` (below the max depth) it ends before NEE and fills `stop`.
fn path_vertex(s: ptr<function, PathState>, stop_depth: u32, rng: ptr<function, u32>, stop: ptr<function, PathPrefix>) {
    let depth = (*s).depth;
    let dir = (*s).dir;
    let prev_bsdf_pdf = (*s).prev_bsdf_pdf;
    var throughput = (*s).throughput;
    var radiance = (*s).radiance;
    let max_depth = frame.max_depth;
    // Every return below but the last ends the path.
    (*s).done = true;
    let hit = trace_closest((*s).origin, dir, FAR);
    if hit.instance == NO_HIT {
        (*s).radiance = radiance + throughput * escaped_radiance(dir, prev_bsdf_pdf);
        return;
    }
    let sp = surface_point(hit, (*s).origin, dir);
    let m = material(sp.material);
    let wo = -dir;
    let sh = orient(sp, wo);
    radiance += throughput * emitted_radiance(sp, m, dir, hit.t, prev_bsdf_pdf);
    (*s).radiance = radiance;
    if depth == max_depth {
        return;
    }
    let bsdf = make_bsdf(base_color_at(m, sp.uv), m.metallic, m.roughness, m.specular);
    let p = sp.position;
    if depth == stop_depth {
        (*stop).stopped = true;
        (*stop).p = p;
        (*stop).sh = sh;
        (*stop).bsdf = bsdf;
        (*stop).wo = wo;
        (*stop).depth = depth;
        return;
    }
    (*s).radiance = radiance + throughput * next_event(p, sh, bsdf, wo, rng);

    // Continue the path by sampling the BSDF.
    let u_lobe = rng_next(rng);
    let bs = bsdf_sample(bsdf, sh.ns, wo, u_lobe, rng_next2(rng));
    if !bs.valid || dot(bs.wi, sh.ng) <= 0.0 {
        return;
    }
    throughput *= bs.f * (dot(sh.ns, bs.wi) / bs.pdf);
    (*s).throughput = throughput;
    (*s).prev_bsdf_pdf = bs.pdf;
    if depth + 1u >= frame.rr_start_depth {
        let survive = min(max_component(throughput), 0.95);
        if rng_next(rng) >= survive {
            return;
        }
        (*s).throughput = throughput / survive;
    }
    (*s).origin = offset_origin(p, sh.ng, bs.wi);
    (*s).dir = bs.wi;
    (*s).depth = depth + 1u;
    (*s).done = depth + 1u > max_depth;
}

// The path loop of `path_radiance`, stopping at the surface vertex `stop_depth` (if the path
// gets there below the max depth) before its NEE: the caller continues from there with the
// same random-number stream.
fn trace_path_prefix(origin_in: vec3f, dir_in: vec3f, prev_bsdf_pdf_in: f32, depth_in: u32, stop_depth: u32, rng: ptr<function, u32>) -> PathPrefix {
    var out: PathPrefix;
    out.stopped = false;
    var s = path_start(origin_in, dir_in, prev_bsdf_pdf_in, depth_in);
    while !s.done {
        path_vertex(&s, stop_depth, rng, &out);
    }
    out.radiance = s.radiance;
    out.throughput = s.throughput;
    return out;
}
