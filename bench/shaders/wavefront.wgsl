// Wavefront path tracer (Laine, Karras & Aila 2013, "Megakernels considered harmful"): the
// megakernel's path loop split into kernels that each run over a queue of live paths. `extend`
// traces each path's next ray, `shade` takes its hit (emission, light samples, the next
// direction) and appends the surviving paths to the other queue (compaction), `shadow` traces the
// light samples' shadow rays, `advance` swaps the queues and writes the next indirect dispatch.
// Every sample keeps its own random-number stream and adds to its own radiance slot in the
// megakernel's order (emission, then next-event estimation, vertex by vertex), so each sample's
// value is the megakernel's and `reduce` sums them per pixel in its chunk order.

import package::scene_types::{GpuMaterial};
import package::scene_features::{HAS_ANALYTIC_LIGHTS, HAS_EMITTERS, HAS_ENVIRONMENT};
import package::scene_bindings::{frame};
import package::scene_tables::{material, light};
import package::scene_geometry::{Hit, NO_HIT, sg_rays_traced, surface_point, trace_any, trace_closest};
import package::pt_sampling::{max_component, power_heuristic, rng_next, rng_next2, rng_seed, sample_uniform_sphere};
import package::pt_bsdf::{bsdf_eval, bsdf_pdf, bsdf_sample, make_bsdf};
import package::pt_lights::{FAR, sample_analytic_light, sample_emitter};
import package::pt_scene::{base_color_at, camera_ray_direction, environment_pdf, escaped_radiance, offset_origin, orient};
import package::pt_integrator::{emitted_radiance};
import package::bench::wavefront_types::{SAMPLES_PER_THREAD, WF_GROUP};
import package::bench::wavefront_bindings::{pt_counters, radiance_sum, wf_control, wf_state};

// wf_control words: live paths in the input queue, paths appended to the output queue, which
// queue is the input (0: A, 1: B), the wave's capacity in paths, then the indirect dispatch of
// the next bounce (x, y, z).
const CTRL_LIVE: u32 = 0u;
const CTRL_NEXT: u32 = 1u;
const CTRL_PARITY: u32 = 2u;
const CTRL_CAPACITY: u32 = 3u;
const CTRL_ARGS: u32 = 4u;

// wf_state regions, in vec4s of a wave of C paths: queue A (4 per path), queue B (4), hits (2),
// per-sample radiance (1), shadow groups (1), shadow rays (3 per light sample).
const PATH_VEC4S: u32 = 4u;
const NO_SAMPLE: u32 = 0xffffffffu;

fn capacity() -> u32 {
    return atomicLoad(&wf_control[CTRL_CAPACITY]);
}
fn queue_base(which: u32) -> u32 {
    return which * PATH_VEC4S * capacity();
}
fn in_base() -> u32 {
    return queue_base(atomicLoad(&wf_control[CTRL_PARITY]));
}
fn out_base() -> u32 {
    return queue_base(1u - atomicLoad(&wf_control[CTRL_PARITY]));
}
fn hit_base() -> u32 {
    return 2u * PATH_VEC4S * capacity();
}
fn radiance_base() -> u32 {
    return hit_base() + 2u * capacity();
}
fn group_base() -> u32 {
    return radiance_base() + capacity();
}
fn ray_base() -> u32 {
    return group_base() + capacity();
}

// Light samples per shading point: every analytic light, one emitter, the environment (each
// only if the scene has that kind), in next_event's order.
fn light_samples() -> u32 {
    var k = 0u;
    if HAS_ANALYTIC_LIGHTS {
        k += frame.analytic_lights;
    }
    if HAS_EMITTERS {
        k += 1u;
    }
    if HAS_ENVIRONMENT {
        k += 1u;
    }
    return k;
}

struct WfPath {
    origin: vec3f,
    slot: u32,
    dir: vec3f,
    prev_bsdf_pdf: f32,
    throughput: vec3f,
    depth: u32,
    rng: u32,
}

fn load_path(base: u32, i: u32) -> WfPath {
    let a = wf_state[base + PATH_VEC4S * i];
    let b = wf_state[base + PATH_VEC4S * i + 1u];
    let c = wf_state[base + PATH_VEC4S * i + 2u];
    let d = wf_state[base + PATH_VEC4S * i + 3u];
    return WfPath(a.xyz, bitcast<u32>(a.w), b.xyz, b.w, c.xyz, bitcast<u32>(c.w), bitcast<u32>(d.x));
}

fn store_path(base: u32, i: u32, p: WfPath) {
    wf_state[base + PATH_VEC4S * i] = vec4f(p.origin, bitcast<f32>(p.slot));
    wf_state[base + PATH_VEC4S * i + 1u] = vec4f(p.dir, p.prev_bsdf_pdf);
    wf_state[base + PATH_VEC4S * i + 2u] = vec4f(p.throughput, bitcast<f32>(p.depth));
    wf_state[base + PATH_VEC4S * i + 3u] = vec4f(bitcast<f32>(p.rng), 0.0, 0.0, 0.0);
}

fn flush_rays() {
    if sg_rays_traced > 0u {
        atomicAdd(&pt_counters[0], sg_rays_traced);
    }
}

// One path per sample of the batch: slot = sample in batch * pixels + pixel. The camera ray as
// trace_main's camera_path draws it.
@compute @workgroup_size(WF_GROUP, 1, 1)
fn wf_generate(@builtin(global_invocation_id) id: vec3u) {
    let pixels = frame.width * frame.height;
    let slot = id.x;
    if slot >= pixels * frame.spp {
        return;
    }
    let pixel_index = slot % pixels;
    let pixel = vec2u(pixel_index % frame.width, pixel_index / frame.width);
    var rng = rng_seed(vec2u(frame.seed_lo, frame.seed_hi), frame.frame, pixel_index, frame.first_sample + slot / pixels);
    let jitter = rng_next2(&rng);
    let dir = camera_ray_direction(frame.camera, vec2f(pixel) + jitter);
    store_path(in_base(), slot, WfPath(frame.camera.position, slot, dir, 0.0, vec3f(1.0), 0u, rng));
    wf_state[radiance_base() + slot] = vec4f(0.0);
}

@compute @workgroup_size(WF_GROUP, 1, 1)
fn wf_extend(@builtin(global_invocation_id) id: vec3u) {
    let i = id.x;
    if i >= atomicLoad(&wf_control[CTRL_LIVE]) {
        return;
    }
    let base = in_base() + PATH_VEC4S * i;
    let origin = wf_state[base].xyz;
    let dir = wf_state[base + 1u].xyz;
    let hit = trace_closest(origin, dir, FAR);
    let h = hit_base() + 2u * i;
    wf_state[h] = vec4f(hit.t, bitcast<f32>(hit.instance), bitcast<f32>(hit.primitive), hit.barycentrics.x);
    wf_state[h + 1u] = vec4f(hit.barycentrics.y, 0.0, 0.0, 0.0);
    flush_rays();
}

// A shadow ray: origin, direction and length, and what it adds unoccluded (without the path's
// throughput). A zero length marks a light sample that needs no ray (next_event's early outs).
fn store_ray(r: u32, origin: vec3f, dir: vec3f, t_max: f32, contribution: vec3f) {
    wf_state[r] = vec4f(origin, t_max);
    wf_state[r + 1u] = vec4f(dir, 0.0);
    wf_state[r + 2u] = vec4f(contribution, 0.0);
}

// path_vertex of pt_integrator after its trace_closest, with next_event's shadow rays written out
// for `wf_shadow` instead of traced.
@compute @workgroup_size(WF_GROUP, 1, 1)
fn wf_shade(@builtin(global_invocation_id) id: vec3u) {
    let i = id.x;
    if i >= atomicLoad(&wf_control[CTRL_LIVE]) {
        return;
    }
    var path = load_path(in_base(), i);
    let h0 = wf_state[hit_base() + 2u * i];
    let h1 = wf_state[hit_base() + 2u * i + 1u];
    let hit = Hit(h0.x, bitcast<u32>(h0.y), bitcast<u32>(h0.z), vec2f(h0.w, h1.x));
    let group = group_base() + i;
    // No light samples unless the vertex reaches next-event estimation.
    wf_state[group] = vec4f(0.0, 0.0, 0.0, bitcast<f32>(NO_SAMPLE));
    let slot = path.slot;
    let dir = path.dir;
    let throughput = path.throughput;
    var radiance = wf_state[radiance_base() + slot].xyz;
    if hit.instance == NO_HIT {
        wf_state[radiance_base() + slot] = vec4f(radiance + throughput * escaped_radiance(dir, path.prev_bsdf_pdf), 0.0);
        return;
    }
    let sp = surface_point(hit, path.origin, dir);
    let m = material(sp.material);
    let wo = -dir;
    let sh = orient(sp, wo);
    radiance += throughput * emitted_radiance(sp, m, dir, hit.t, path.prev_bsdf_pdf);
    wf_state[radiance_base() + slot] = vec4f(radiance, 0.0);
    if path.depth == frame.max_depth {
        return;
    }
    let bsdf = make_bsdf(base_color_at(m, sp.uv), m.metallic, m.roughness, m.specular);
    let p = sp.position;
    var rng = path.rng;

    // next_event's light samples, drawn in its order; their rays go to wf_shadow.
    wf_state[group] = vec4f(throughput, bitcast<f32>(slot));
    var r = ray_base() + 3u * light_samples() * i;
    if HAS_ANALYTIC_LIGHTS {
        for (var l = 0u; l < frame.analytic_lights; l++) {
            let ls = sample_analytic_light(light(l), p, rng_next2(&rng));
            var t_max = 0.0;
            var c = vec3f(0.0);
            if dot(ls.wi, sh.ng) > 0.0 && max_component(ls.weight) > 0.0 {
                let f = bsdf_eval(bsdf, sh.ns, wo, ls.wi);
                if max_component(f) > 0.0 {
                    var w = 1.0;
                    if ls.pdf > 0.0 {
                        w = power_heuristic(ls.pdf, bsdf_pdf(bsdf, sh.ns, wo, ls.wi));
                    }
                    c = f * dot(sh.ns, ls.wi) * ls.weight * w;
                    t_max = ls.dist * (1.0 - 1.0e-4);
                }
            }
            store_ray(r, offset_origin(p, sh.ng, ls.wi), ls.wi, t_max, c);
            r += 3u;
        }
    }
    if HAS_EMITTERS {
        var t_max = 0.0;
        var c = vec3f(0.0);
        var wi = vec3f(0.0);
        let emitter_count = frame.emitters;
        if emitter_count > 0u {
            let u_select = rng_next(&rng);
            let ls = sample_emitter(frame.analytic_lights, emitter_count, p, u_select, rng_next2(&rng));
            wi = ls.wi;
            if ls.pdf > 0.0 && dot(ls.wi, sh.ng) > 0.0 {
                let f = bsdf_eval(bsdf, sh.ns, wo, ls.wi);
                if max_component(f) > 0.0 {
                    let w = power_heuristic(ls.pdf, bsdf_pdf(bsdf, sh.ns, wo, ls.wi));
                    c = f * dot(sh.ns, ls.wi) * ls.weight * w;
                    t_max = ls.dist * (1.0 - 1.0e-3);
                }
            }
        }
        store_ray(r, offset_origin(p, sh.ng, wi), wi, t_max, c);
        r += 3u;
    }
    if HAS_ENVIRONMENT {
        var t_max = 0.0;
        var c = vec3f(0.0);
        var wi = vec3f(0.0);
        let env_pdf = environment_pdf();
        if env_pdf > 0.0 {
            wi = sample_uniform_sphere(rng_next2(&rng));
            if dot(wi, sh.ng) > 0.0 {
                let f = bsdf_eval(bsdf, sh.ns, wo, wi);
                if max_component(f) > 0.0 {
                    let w = power_heuristic(env_pdf, bsdf_pdf(bsdf, sh.ns, wo, wi));
                    c = f * dot(sh.ns, wi) * frame.environment * (w / env_pdf);
                    t_max = FAR;
                }
            }
        }
        store_ray(r, offset_origin(p, sh.ng, wi), wi, t_max, c);
    }

    // Continue the path by sampling the BSDF (path_vertex's tail).
    let u_lobe = rng_next(&rng);
    let bs = bsdf_sample(bsdf, sh.ns, wo, u_lobe, rng_next2(&rng));
    if !bs.valid || dot(bs.wi, sh.ng) <= 0.0 {
        return;
    }
    var next_throughput = throughput * (bs.f * (dot(sh.ns, bs.wi) / bs.pdf));
    let depth = path.depth;
    if depth + 1u >= frame.rr_start_depth {
        let survive = min(max_component(next_throughput), 0.95);
        if rng_next(&rng) >= survive {
            return;
        }
        next_throughput = next_throughput / survive;
    }
    if depth + 1u > frame.max_depth {
        return;
    }
    path.origin = offset_origin(p, sh.ng, bs.wi);
    path.dir = bs.wi;
    path.prev_bsdf_pdf = bs.pdf;
    path.throughput = next_throughput;
    path.depth = depth + 1u;
    path.rng = rng;
    let next = atomicAdd(&wf_control[CTRL_NEXT], 1u);
    store_path(out_base(), next, path);
}

// The light samples of each shaded vertex, traced in next_event's order and summed as it sums
// them: (analytic + emitter) + environment.
@compute @workgroup_size(WF_GROUP, 1, 1)
fn wf_shadow(@builtin(global_invocation_id) id: vec3u) {
    let i = id.x;
    if i >= atomicLoad(&wf_control[CTRL_LIVE]) {
        return;
    }
    let group = wf_state[group_base() + i];
    let slot = bitcast<u32>(group.w);
    if slot == NO_SAMPLE {
        return;
    }
    var r = ray_base() + 3u * light_samples() * i;
    var analytic = vec3f(0.0);
    var emitter = vec3f(0.0);
    var environment = vec3f(0.0);
    if HAS_ANALYTIC_LIGHTS {
        for (var l = 0u; l < frame.analytic_lights; l++) {
            let o = wf_state[r];
            if o.w > 0.0 && !trace_any(o.xyz, wf_state[r + 1u].xyz, o.w) {
                analytic += wf_state[r + 2u].xyz;
            }
            r += 3u;
        }
    }
    if HAS_EMITTERS {
        let o = wf_state[r];
        if o.w > 0.0 && !trace_any(o.xyz, wf_state[r + 1u].xyz, o.w) {
            emitter = wf_state[r + 2u].xyz;
        }
        r += 3u;
    }
    if HAS_ENVIRONMENT {
        let o = wf_state[r];
        if o.w > 0.0 && !trace_any(o.xyz, wf_state[r + 1u].xyz, o.w) {
            environment = wf_state[r + 2u].xyz;
        }
    }
    let radiance = wf_state[radiance_base() + slot].xyz;
    wf_state[radiance_base() + slot] = vec4f(radiance + group.xyz * (analytic + emitter + environment), 0.0);
    flush_rays();
}

// Between bounces: the paths appended become the input queue, and the next bounce's kernels are
// dispatched over them.
@compute @workgroup_size(1, 1, 1)
fn wf_advance() {
    let live = atomicLoad(&wf_control[CTRL_NEXT]);
    atomicStore(&wf_control[CTRL_LIVE], live);
    atomicStore(&wf_control[CTRL_NEXT], 0u);
    atomicStore(&wf_control[CTRL_PARITY], 1u - atomicLoad(&wf_control[CTRL_PARITY]));
    atomicStore(&wf_control[CTRL_ARGS], (live + WF_GROUP - 1u) / WF_GROUP);
    atomicStore(&wf_control[CTRL_ARGS + 1u], 1u);
    atomicStore(&wf_control[CTRL_ARGS + 2u], 1u);
}

// Per pixel: each chunk of SAMPLES_PER_THREAD samples summed in sample order, the chunks added in
// order, then added to the running sum (trace_main's and accumulate_main's order).
@compute @workgroup_size(8, 8, 1)
fn wf_reduce(@builtin(global_invocation_id) id: vec3u) {
    if id.x >= frame.width || id.y >= frame.height {
        return;
    }
    let pixels = frame.width * frame.height;
    let index = id.y * frame.width + id.x;
    let chunks = (frame.spp + SAMPLES_PER_THREAD - 1u) / SAMPLES_PER_THREAD;
    var sum = vec3f(0.0);
    for (var c = 0u; c < chunks; c++) {
        var chunk = vec3f(0.0);
        let count = min(SAMPLES_PER_THREAD, frame.spp - c * SAMPLES_PER_THREAD);
        for (var s = 0u; s < count; s++) {
            chunk += wf_state[radiance_base() + (c * SAMPLES_PER_THREAD + s) * pixels + index].xyz;
        }
        sum += chunk;
    }
    var previous = vec4f(0.0);
    if frame.accumulate != 0u {
        previous = radiance_sum[index];
    }
    radiance_sum[index] = previous + vec4f(sum, f32(frame.spp));
}
