// Volumetric path tracing for unbiased references (media::gpu::VolumePathPass): the path
// tracer's loop (render/shaders/pt_integrator.wgsl: Lambert + GGX, NEE + MIS with the power
// heuristic, Russian roulette) with one medium (isotropic phase, albedo vp.albedo): delta
// tracking samples free paths, every shadow ray (surface and medium vertices) is attenuated by
// ratio tracking (or the track-length estimate, vp.shadow), and positional lights (point, spot)
// are also sampled by equiangular sampling on every segment in the medium, combined with the
// free-flight sample by MIS (Sec. 5.2): weights naive g(X̄), jackknife Re g(X̄ + iS) or
// Miller et al.'s, combined by Eq. 9 (unbiased) or Eq. 10. vp.mis = none: delta tracking only.
// Medium emission (vp.emission, radiance per unit extinction: the source term σ_t(x) ε) is
// collected at every real collision of delta tracking, whose density is T(t) σ_t(t): an unbiased
// estimate of ∫ T σ_t ε dt.

import package::scene_types::{GpuMaterial};
import package::scene_bindings::{frame, lights, materials};
import package::scene_geometry::{NO_HIT, surface_point, trace_any, trace_closest};
import package::pt_sampling::{max_component, power_heuristic, rng_next, rng_next2, sample_uniform_sphere};
import package::pt_bsdf::{Bsdf, bsdf_eval, bsdf_pdf, bsdf_sample, make_bsdf};
import package::pt_lights::{FAR, LIGHT_DIRECTIONAL, sample_analytic_light, sample_emitter};
import package::pt_scene::{Shading, base_color_at, environment_pdf, escaped_radiance, offset_origin, orient};
import package::pt_integrator::{emitted_radiance};
import package::media::types::{RaySegment};
import package::media::media_grid::{BIG, medium_segment, mu_point};
import package::media::media_tracking::{delta_tracking, ratio_tracking, track_length};
import package::media::media_optical_depth::{od_estimate, od_prepare, od_x};
import package::media::media_mis::{equiangular_new, equiangular_pdf, equiangular_sample, mis_free_flight, mis_jackknife, mis_miller, mis_naive, mis_other};
import package::media::volume_path_bindings::{vp};

const INV_4PI: f32 = 0.0795774715459477;
const MIS_NONE: u32 = 0u;
const MIS_NAIVE: u32 = 1u;
const MIS_JACKKNIFE: u32 = 2u;
const MIS_MILLER: u32 = 3u;
const SHADOW_TRACK_LENGTH: u32 = 1u;

// A scattering vertex: on a surface (sh, bsdf) or in the medium (isotropic phase).
struct Vertex {
    p: vec3f,
    in_medium: bool,
    sh: Shading,
    bsdf: Bsdf,
    wo: vec3f,
}

// f · cos for surfaces (cos unclamped, as pt_integrator), the phase function in the medium.
fn scatter_f(v: Vertex, wi: vec3f) -> vec3f {
    if v.in_medium {
        return vec3f(INV_4PI);
    }
    return bsdf_eval(v.bsdf, v.sh.ns, v.wo, wi) * dot(v.sh.ns, wi);
}

fn scatter_pdf(v: Vertex, wi: vec3f) -> f32 {
    if v.in_medium {
        return INV_4PI;
    }
    return bsdf_pdf(v.bsdf, v.sh.ns, v.wo, wi);
}

fn faces(v: Vertex, wi: vec3f) -> bool {
    return v.in_medium || dot(wi, v.sh.ng) > 0.0;
}

fn shadow_origin(v: Vertex, wi: vec3f) -> vec3f {
    return select(offset_origin(v.p, v.sh.ng, wi), v.p, v.in_medium);
}

// Transmittance of the part of a shadow ray inside the medium.
fn shadow_transmittance(o: vec3f, wi: vec3f, dist: f32, rng: ptr<function, u32>) -> f32 {
    let s = medium_segment(o, wi, dist);
    if s.t0 >= s.t1 {
        return 1.0;
    }
    if vp.shadow == SHADOW_TRACK_LENGTH {
        return track_length(s, rng);
    }
    return ratio_tracking(s, rng);
}

fn visibility(o: vec3f, wi: vec3f, dist: f32, rng: ptr<function, u32>) -> f32 {
    if trace_any(o, wi, dist) {
        return 0.0;
    }
    return shadow_transmittance(o, wi, dist, rng);
}

// The part of segment s from its start to t.
fn head(s: RaySegment, t: f32) -> RaySegment {
    return RaySegment(s.origin, s.t0, s.dir, t);
}

// An estimate of the free-flight weight g = T(t) μ(t) / (p0(t) + T(t) μ(t)) (`other` false) or
// of 1 − g (`other` true), T from the segment's start, by vp.mis; its own random numbers.
fn mis_weight(s: RaySegment, t: f32, mu: f32, p0: f32, other: bool, rng: ptr<function, u32>) -> f32 {
    let h = head(s, t);
    if vp.mis == MIS_MILLER {
        let w = mis_miller(mu, p0, ratio_tracking(h, rng));
        return select(w, 1.0 - w, other);
    }
    let r = select(mis_free_flight(mu, p0), mis_other(mu, p0), other);
    let prep = od_prepare(h, true);
    od_estimate(h, prep, 2u, vp.samples, true, true, rng);
    if vp.mis == MIS_NAIVE {
        return mis_naive(r, 0.5 * (od_x[0] + od_x[1]));
    }
    return mis_jackknife(r, od_x[0], od_x[1]);
}

// Strategy 0 of Sec. 5.2 on a segment in the medium: one equiangular sample per positional
// light, weighted as Eq. 9 (w̃0 T̃ μ L_s / p0, T̃ by ratio tracking) or Eq. 10 (g̃ L_s).
fn equiangular_lights(s: RaySegment, origin: vec3f, dir: vec3f, rng: ptr<function, u32>) -> vec3f {
    var sum = vec3f(0.0);
    for (var i = 0u; i < frame.analytic_lights; i++) {
        let l = lights[i];
        if l.kind == LIGHT_DIRECTIONAL {
            continue;
        }
        let eq = equiangular_new(origin, dir, l.p0, s.t0, s.t1);
        let t = equiangular_sample(eq, rng_next(rng));
        let p0 = equiangular_pdf(eq, t);
        let mu = mu_point(s, t);
        let ls = sample_analytic_light(l, origin + dir * t, rng_next2(rng));
        if mu <= 0.0 || max_component(ls.weight) <= 0.0 {
            continue;
        }
        let vis = visibility(origin + dir * t, ls.wi, ls.dist * (1.0 - 1.0e-4), rng);
        if vis <= 0.0 {
            continue;
        }
        let inscattered = vp.albedo * INV_4PI * ls.weight * vis;
        if vp.eq10 != 0u {
            sum += mis_weight(s, t, mu, p0, false, rng) * inscattered;
        } else {
            let w0 = mis_weight(s, t, mu, p0, true, rng);
            let tr = ratio_tracking(head(s, t), rng);
            sum += (w0 * tr * mu / p0) * inscattered;
        }
    }
    return sum;
}

// Next-event estimation at v: every analytic light, one emissive triangle, the environment, as
// pt_integrator's next_event, with the shadow rays' transmittance. At a medium vertex reached by
// delta tracking on segment s of the world ray (origin, dir) at t (with equiangular sampling
// on), a positional light's estimate is strategy 1 of Sec. 5.2 and weighted by w̃1(t) (Eq. 9
// and Eq. 10 alike).
fn next_event(v: Vertex, s: RaySegment, origin: vec3f, dir: vec3f, t: f32, rng: ptr<function, u32>) -> vec3f {
    var radiance = vec3f(0.0);
    for (var i = 0u; i < frame.analytic_lights; i++) {
        let l = lights[i];
        let ls = sample_analytic_light(l, v.p, rng_next2(rng));
        if !faces(v, ls.wi) || max_component(ls.weight) <= 0.0 {
            continue;
        }
        let f = scatter_f(v, ls.wi);
        if max_component(abs(f)) <= 0.0 {
            continue;
        }
        let vis = visibility(shadow_origin(v, ls.wi), ls.wi, ls.dist * (1.0 - 1.0e-4), rng);
        if vis <= 0.0 {
            continue;
        }
        var w = 1.0;
        if ls.pdf > 0.0 {
            w = power_heuristic(ls.pdf, scatter_pdf(v, ls.wi));
        }
        if v.in_medium && vp.mis != MIS_NONE && l.kind != LIGHT_DIRECTIONAL {
            let eq = equiangular_new(origin, dir, l.p0, s.t0, s.t1);
            w = mis_weight(s, t, mu_point(s, t), equiangular_pdf(eq, t), false, rng);
        }
        radiance += f * ls.weight * (vis * w);
    }
    if frame.emitters > 0u {
        let u_select = rng_next(rng);
        let ls = sample_emitter(frame.analytic_lights, frame.emitters, v.p, u_select, rng_next2(rng));
        if ls.pdf > 0.0 && faces(v, ls.wi) {
            let f = scatter_f(v, ls.wi);
            if max_component(abs(f)) > 0.0 {
                let vis = visibility(shadow_origin(v, ls.wi), ls.wi, ls.dist * (1.0 - 1.0e-3), rng);
                radiance += f * ls.weight * (vis * power_heuristic(ls.pdf, scatter_pdf(v, ls.wi)));
            }
        }
    }
    let env_pdf = environment_pdf();
    if env_pdf > 0.0 {
        let wi = sample_uniform_sphere(rng_next2(rng));
        if faces(v, wi) {
            let f = scatter_f(v, wi);
            if max_component(abs(f)) > 0.0 {
                let vis = visibility(shadow_origin(v, wi), wi, FAR, rng);
                radiance += f * frame.environment * (vis * power_heuristic(env_pdf, scatter_pdf(v, wi)) / env_pdf);
            }
        }
    }
    return radiance;
}

// Radiance along the camera ray (origin, dir), up to the frame's max depth; medium and surface
// vertices count alike.
fn volume_path_radiance(origin_in: vec3f, dir_in: vec3f, rng: ptr<function, u32>) -> vec3f {
    var origin = origin_in;
    var dir = dir_in;
    var throughput = vec3f(1.0);
    var radiance = vec3f(0.0);
    var prev_pdf = 0.0;
    let max_depth = frame.max_depth;
    for (var depth = 0u; depth <= max_depth; depth++) {
        let hit = trace_closest(origin, dir, FAR);
        let t_hit = select(hit.t, FAR, hit.instance == NO_HIT);
        let s = medium_segment(origin, dir, t_hit);
        var t_collision = BIG;
        if s.t0 < s.t1 {
            if vp.mis != MIS_NONE && depth < max_depth {
                radiance += throughput * equiangular_lights(s, origin, dir, rng);
            }
            t_collision = delta_tracking(s, rng);
        }
        var v: Vertex;
        if t_collision < BIG {
            // Emission at the collision, before its scattering weight (ε per unit extinction).
            radiance += throughput * vp.emission;
            if depth == max_depth {
                break;
            }
            v.p = origin + dir * t_collision;
            v.in_medium = true;
            v.wo = -dir;
            // Delta tracking's weight at a real collision: σ_s / σ_t.
            throughput *= vp.albedo;
            radiance += throughput * next_event(v, s, origin, dir, t_collision, rng);
            dir = sample_uniform_sphere(rng_next2(rng));
            prev_pdf = INV_4PI;
        } else {
            if hit.instance == NO_HIT {
                radiance += throughput * escaped_radiance(dir, prev_pdf);
                break;
            }
            let sp = surface_point(hit, origin, dir);
            let m = materials[sp.material];
            v.wo = -dir;
            v.sh = orient(sp, v.wo);
            v.in_medium = false;
            v.p = sp.position;
            radiance += throughput * emitted_radiance(sp, m, dir, hit.t, prev_pdf);
            if depth == max_depth {
                break;
            }
            v.bsdf = make_bsdf(base_color_at(m, sp.uv), m.metallic, m.roughness, m.specular);
            radiance += throughput * next_event(v, s, origin, dir, 0.0, rng);
            let u_lobe = rng_next(rng);
            let bs = bsdf_sample(v.bsdf, v.sh.ns, v.wo, u_lobe, rng_next2(rng));
            if !bs.valid || dot(bs.wi, v.sh.ng) <= 0.0 {
                break;
            }
            throughput *= bs.f * (dot(v.sh.ns, bs.wi) / bs.pdf);
            prev_pdf = bs.pdf;
            dir = bs.wi;
        }
        if depth + 1u >= frame.rr_start_depth {
            let survive = min(max_component(throughput), 0.95);
            if rng_next(rng) >= survive {
                break;
            }
            throughput /= survive;
        }
        origin = select(offset_origin(v.p, v.sh.ng, dir), v.p, v.in_medium);
    }
    return radiance;
}
