// The random-walk ground truth of subsurface materials (media::gpu::SubsurfacePathPass): the
// path tracer's loop (Lambert + GGX, NEE + MIS, Russian roulette; pt_integrator.wgsl) where a
// surface whose material is subsurface (coefficients[2m].w = 1) is an index-matched boundary of
// a homogeneous medium filling its mesh: the ray passes it unbent and walks inside (free flights
// Exp(σ_t), isotropic phase, single-scattering albedo α, scene::SubsurfaceMedium) until it
// crosses the boundary again, and the path goes on from there in the same direction. One
// channel's σ_t draws each free flight, the channel chosen in proportion to the throughput, and
// the sample is weighted by the mixture pdf over the three channels (one-sample MIS with the
// balance heuristic, as Chiang, Kutz & Burley 2016's chromatic walk; media_free_flight.wgsl). At every scattering
// vertex: NEE of the lights through the boundary (transmittance exp(−σ_t d) to where the shadow
// ray leaves the mesh, then the rest as any shadow ray). A walk is one vertex of the path (its
// exit continues at the next depth); walks longer than sp.max_events are dropped (absorbed).

import package::scene_bindings::{frame};
import package::scene_tables::{material, light};
import package::scene_geometry::{NO_HIT, surface_point, trace_any, trace_closest};
import package::pt_sampling::{max_component, power_heuristic, rng_next, rng_next2, sample_uniform_sphere};
import package::pt_bsdf::{bsdf_sample, make_bsdf};
import package::pt_lights::{FAR, sample_analytic_light, sample_emitter};
import package::pt_scene::{base_color_at, camera_ray_direction, environment_pdf, escaped_radiance, offset_origin, orient};
import package::pt_integrator::{emitted_radiance, next_event};
import package::pt_sampling::{rng_seed};
import package::media::subsurface_path_bindings::{coefficients, samples, sp};
import package::media::media_free_flight::{channel_probabilities, free_flight_pdf, free_flight_survival, sample_free_flight};

const INV_4PI: f32 = 0.0795774715459477;

fn is_subsurface(m: u32) -> bool {
    return m < sp.materials && coefficients[2u * m].w > 0.0;
}

// Transmittance of a shadow ray from p inside the medium of extinction sigma_t to a light at
// dist: through the medium to the boundary, then occlusion by anything else.
fn shadow_from_inside(p: vec3f, wi: vec3f, dist: f32, sigma_t: vec3f) -> vec3f {
    let h = trace_closest(p, wi, dist);
    if h.instance == NO_HIT {
        return exp(-sigma_t * dist);
    }
    let s = surface_point(h, p, wi);
    if trace_any(offset_origin(s.position, s.geometric_normal, wi), wi, (dist - h.t) * (1.0 - 1.0e-4)) {
        return vec3f(0.0);
    }
    return exp(-sigma_t * h.t);
}

// NEE at a scattering vertex p inside the medium (phase 1/4π), as pt_integrator's next_event.
fn next_event_inside(p: vec3f, sigma_t: vec3f, rng: ptr<function, u32>) -> vec3f {
    var radiance = vec3f(0.0);
    for (var i = 0u; i < frame.analytic_lights; i++) {
        let ls = sample_analytic_light(light(i), p, rng_next2(rng));
        if max_component(ls.weight) <= 0.0 {
            continue;
        }
        var w = 1.0;
        if ls.pdf > 0.0 {
            w = power_heuristic(ls.pdf, INV_4PI);
        }
        radiance += ls.weight * shadow_from_inside(p, ls.wi, ls.dist * (1.0 - 1.0e-4), sigma_t) * (INV_4PI * w);
    }
    if frame.emitters > 0u {
        let u_select = rng_next(rng);
        let ls = sample_emitter(frame.analytic_lights, frame.emitters, p, u_select, rng_next2(rng));
        if ls.pdf > 0.0 {
            let tr = shadow_from_inside(p, ls.wi, ls.dist * (1.0 - 1.0e-3), sigma_t);
            radiance += ls.weight * tr * (INV_4PI * power_heuristic(ls.pdf, INV_4PI));
        }
    }
    let env_pdf = environment_pdf();
    if env_pdf > 0.0 {
        let wi = sample_uniform_sphere(rng_next2(rng));
        let tr = shadow_from_inside(p, wi, FAR, sigma_t);
        radiance += frame.environment * tr * (INV_4PI * power_heuristic(env_pdf, INV_4PI) / env_pdf);
    }
    return radiance;
}

// Where a walk left the medium: the exit point and direction, the distance from its last
// vertex, and whether it left at all.
struct WalkExit {
    p: vec3f,
    dir: vec3f,
    ng: vec3f,
    dist: f32,
    scattered: bool,
    left: bool,
}

// A walk into material m's medium from `entry` (on the boundary) along `dir`: NEE into
// `radiance`, the path's throughput updated, the exit returned.
fn random_walk(m: u32, entry: vec3f, dir_in: vec3f, throughput: ptr<function, vec3f>, radiance: ptr<function, vec3f>, rng: ptr<function, u32>) -> WalkExit {
    let sigma_t = coefficients[2u * m].xyz;
    let sigma_s = coefficients[2u * m + 1u].xyz * sigma_t;
    var out: WalkExit;
    out.left = false;
    out.scattered = false;
    var p = entry;
    var dir = dir_in;
    for (var event = 0u; event < sp.max_events; event++) {
        let beta = *throughput;
        if beta.x + beta.y + beta.z <= 0.0 {
            return out;
        }
        let q = channel_probabilities(beta);
        let u = rng_next(rng);
        let t = sample_free_flight(sigma_t, q, u, rng_next(rng));
        let h = trace_closest(p, dir, t);
        if h.instance != NO_HIT {
            let tr = exp(-sigma_t * h.t);
            *throughput = beta * tr / free_flight_survival(sigma_t, q, h.t);
            let s = surface_point(h, p, dir);
            out.p = s.position;
            out.ng = s.geometric_normal;
            out.dir = dir;
            out.dist = h.t;
            out.left = true;
            return out;
        }
        let tr = exp(-sigma_t * t);
        *throughput = beta * sigma_s * tr / free_flight_pdf(sigma_t, q, t);
        p += dir * t;
        out.scattered = true;
        *radiance += *throughput * next_event_inside(p, sigma_t, rng);
        dir = sample_uniform_sphere(rng_next2(rng));
    }
    return out;
}

// Radiance along the camera ray (origin, dir), up to the frame's max depth.
fn subsurface_path_radiance(origin_in: vec3f, dir_in: vec3f, rng: ptr<function, u32>) -> vec3f {
    var origin = origin_in;
    var dir = dir_in;
    var throughput = vec3f(1.0);
    var radiance = vec3f(0.0);
    var prev_pdf = 0.0;
    // Distance from the last scattering vertex to `origin` (a walk's exit point).
    var carried = 0.0;
    let max_depth = frame.max_depth;
    for (var depth = 0u; depth <= max_depth; depth++) {
        let hit = trace_closest(origin, dir, FAR);
        if hit.instance == NO_HIT {
            radiance += throughput * escaped_radiance(dir, prev_pdf);
            break;
        }
        let s = surface_point(hit, origin, dir);
        let m = material(s.material);
        let travelled = carried + hit.t;
        radiance += throughput * emitted_radiance(s, m, dir, travelled, prev_pdf);
        carried = 0.0;
        if depth == max_depth {
            break;
        }
        if is_subsurface(s.material) {
            let entry = offset_origin(s.position, s.geometric_normal, dir);
            let exit = random_walk(s.material, entry, dir, &throughput, &radiance, rng);
            if !exit.left {
                break;
            }
            origin = offset_origin(exit.p, exit.ng, exit.dir);
            dir = exit.dir;
            carried = select(travelled + exit.dist, exit.dist, exit.scattered);
            if exit.scattered {
                prev_pdf = INV_4PI;
            }
            continue;
        }
        let wo = -dir;
        let sh = orient(s, wo);
        let bsdf = make_bsdf(base_color_at(m, s.uv), m.metallic, m.roughness, m.specular);
        radiance += throughput * next_event(s.position, sh, bsdf, wo, rng);
        let bs = bsdf_sample(bsdf, sh.ns, wo, rng_next(rng), rng_next2(rng));
        if !bs.valid || dot(bs.wi, sh.ng) <= 0.0 {
            break;
        }
        throughput *= bs.f * (dot(sh.ns, bs.wi) / bs.pdf);
        prev_pdf = bs.pdf;
        if depth + 1u >= frame.rr_start_depth {
            let survive = min(max_component(throughput), 0.95);
            if rng_next(rng) >= survive {
                break;
            }
            throughput /= survive;
        }
        origin = offset_origin(s.position, sh.ng, bs.wi);
        dir = bs.wi;
    }
    return radiance;
}

@compute @workgroup_size(64)
fn subsurface_path(@builtin(global_invocation_id) id: vec3u) {
    // Dispatches wider than 65535 workgroups of 64 continue in y.
    let i = id.x + id.y * (65535u * 64u);
    let pixels = frame.width * frame.height;
    if i >= pixels * sp.spp {
        return;
    }
    let pixel = i / sp.spp;
    let sample = sp.first_sample + i % sp.spp;
    var rng = rng_seed(vec2u(frame.seed_lo, frame.seed_hi), frame.frame, pixel, sample);
    let jitter = rng_next2(&rng);
    let dir = camera_ray_direction(frame.camera, vec2f(f32(pixel % frame.width), f32(pixel / frame.width)) + jitter);
    samples[i] = vec4f(subsurface_path_radiance(frame.camera.position, dir, &rng), 0.0);
}
