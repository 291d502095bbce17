// Volumetric path tracing for unbiased references (media::gpu::VolumePathPass): the path
// tracer's loop (render/shaders/pt_integrator.wgsl: Lambert + GGX, NEE + MIS with the power
// heuristic, Russian roulette) with one or several media (isotropic phase, albedo per medium,
// optics[2i]): delta tracking samples free paths, every shadow ray (surface and medium
// vertices) is attenuated by ratio tracking (or the track-length estimate, or the jackknife:
// Eq. 3 from vp.shadow_estimates optical depths summed over the media, vp.shadow), and
// positional lights (point, spot) are also sampled by equiangular sampling on the part of every
// segment inside media, combined with the free-flight sample by MIS (Sec. 5.2): weights naive
// g(X̄), jackknife Re g(X̄ + iS) or Miller et al.'s, combined by Eq. 9 (unbiased) or Eq. 10.
// vp.mis = none: delta tracking only.
// Several media: their extinctions add. The first real collision is the earliest of each
// medium's delta-tracking collision (the first event of a sum of independent processes, hazard
// Σ μ_k; it lies in medium k with probability μ_k / Σ μ), scattering with that medium's albedo;
// transmittances multiply (one ratio tracking per medium); the MIS weights see μ = Σ μ_k and
// optical-depth estimates summed over the media, and the equiangular sample scatters with
// σ_s = Σ albedo_k μ_k.
// Medium emission (optics[2i + 1], radiance per unit extinction: the source term σ_t(x) ε) is
// collected at every real collision of delta tracking, whose density is T(t) σ_t(t): an unbiased
// estimate of ∫ T σ_t ε dt.

import package::scene_types::{GpuMaterial};
import package::scene_bindings::{frame};
import package::scene_tables::{material, light};
import package::scene_geometry::{NO_HIT, surface_point, trace_any, trace_closest};
import package::pt_sampling::{max_component, power_heuristic, rng_next, rng_next2, sample_uniform_sphere};
import package::pt_bsdf::{Bsdf, bsdf_eval, bsdf_pdf, bsdf_sample, make_bsdf};
import package::pt_lights::{FAR, LIGHT_DIRECTIONAL, sample_analytic_light, sample_emitter};
import package::pt_scene::{Shading, base_color_at, environment_pdf, escaped_radiance, offset_origin, orient};
import package::pt_integrator::{emitted_radiance};
import package::media::types::{RaySegment};
import package::media::media_grid::{BIG, media_count, medium_segment, mu_point, select_medium};
import package::media::media_tracking::{delta_tracking, ratio_tracking, regular_tracking, track_length};
import package::media::media_optical_depth::{od_estimate, od_prepare, od_x, tied_sample_count};
import package::media::media_jackknife::{jackknife_estimates};
import package::media::media_mis::{equiangular_new, equiangular_pdf, equiangular_sample, mis_free_flight, mis_jackknife, mis_miller, mis_naive, mis_other};
import package::media::volume_path_bindings::{optics, vp};

const INV_4PI: f32 = 0.0795774715459477;
const MIS_NONE: u32 = 0u;
const MIS_NAIVE: u32 = 1u;
const MIS_JACKKNIFE: u32 = 2u;
const MIS_MILLER: u32 = 3u;
const SHADOW_TRACK_LENGTH: u32 = 1u;
const SHADOW_JACKKNIFE: u32 = 2u;

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

// A ray through the media: origin, unit direction, and where it ends (a surface, or FAR).
struct MediaRay {
    origin: vec3f,
    dir: vec3f,
    t_max: f32,
}

// The part of the ray (origin, dir) in [0, t_max] inside medium i's box, medium i selected.
fn segment_in(i: u32, origin: vec3f, dir: vec3f, t_max: f32) -> RaySegment {
    select_medium(i);
    return medium_segment(origin, dir, t_max);
}

// [t0, t1] of the ray covered by the media's boxes; t0 >= t1 where it meets none.
fn media_span(r: MediaRay) -> vec2f {
    var span = vec2f(BIG, 0.0);
    for (var i = 0u; i < media_count(); i++) {
        let s = segment_in(i, r.origin, r.dir, r.t_max);
        if s.t0 < s.t1 {
            span = vec2f(min(span.x, s.t0), max(span.y, s.t1));
        }
    }
    return span;
}

// At t on the ray: (σ_s, μ) summed over the media, σ_s = Σ albedo_k μ_k per channel.
fn extinction_at(r: MediaRay, t: f32) -> vec4f {
    var sum = vec4f(0.0);
    for (var i = 0u; i < media_count(); i++) {
        let s = segment_in(i, r.origin, r.dir, r.t_max);
        if s.t0 < s.t1 && s.t0 <= t && t <= s.t1 {
            let mu = mu_point(s, t);
            sum += vec4f(optics[2u * i].xyz * mu, mu);
        }
    }
    return sum;
}

// Transmittance of the ray from its origin to t by ratio tracking: the product over the media.
fn ratio_tracking_to(r: MediaRay, t: f32, rng: ptr<function, u32>) -> f32 {
    var tr = 1.0;
    for (var i = 0u; i < media_count(); i++) {
        let s = segment_in(i, r.origin, r.dir, min(t, r.t_max));
        if s.t0 < s.t1 {
            tr *= ratio_tracking(s, rng);
        }
    }
    return tr;
}

// Exact transmittance of the ray from its origin to t: regular tracking through every medium's
// voxels (Eq. 9's T̃ when vp.eq9_exact is set).
fn exact_transmittance_to(r: MediaRay, t: f32) -> f32 {
    var tau = 0.0;
    for (var i = 0u; i < media_count(); i++) {
        let s = segment_in(i, r.origin, r.dir, min(t, r.t_max));
        if s.t0 < s.t1 {
            tau += regular_tracking(s);
        }
    }
    return exp(-tau);
}

// The jackknife estimate of the transmittance of the parts of a shadow ray inside the media:
// m optical-depth estimates, each a sum over the media (their extinctions add), then Eq. 3.
fn jackknife_shadow(o: vec3f, wi: vec3f, dist: f32, rng: ptr<function, u32>) -> f32 {
    var x: array<f32, 9>;
    for (var i = 0u; i < media_count(); i++) {
        let s = segment_in(i, o, wi, dist);
        if s.t0 >= s.t1 {
            continue;
        }
        let prep = od_prepare(s, true);
        var n = vp.shadow_samples;
        if vp.shadow_step > 0.0 {
            n = tied_sample_count(prep.x, vp.shadow_step);
        }
        od_estimate(s, prep, vp.shadow_estimates, n, true, true, rng);
        for (var k = 0u; k < vp.shadow_estimates; k++) {
            x[k] += od_x[k];
        }
    }
    return jackknife_estimates(x, vp.shadow_estimates);
}

// Transmittance of the parts of a shadow ray inside the media (a product over them).
fn shadow_transmittance(o: vec3f, wi: vec3f, dist: f32, rng: ptr<function, u32>) -> f32 {
    if vp.shadow == SHADOW_JACKKNIFE {
        return jackknife_shadow(o, wi, dist, rng);
    }
    var tr = 1.0;
    for (var i = 0u; i < media_count(); i++) {
        let s = segment_in(i, o, wi, dist);
        if s.t0 >= s.t1 {
            continue;
        }
        if vp.shadow == SHADOW_TRACK_LENGTH {
            tr *= track_length(s, rng);
        } else {
            tr *= ratio_tracking(s, rng);
        }
    }
    return tr;
}

fn visibility(o: vec3f, wi: vec3f, dist: f32, rng: ptr<function, u32>) -> f32 {
    if trace_any(o, wi, dist) {
        return 0.0;
    }
    return shadow_transmittance(o, wi, dist, rng);
}

// An estimate of the free-flight weight g = T(t) μ(t) / (p0(t) + T(t) μ(t)) (`other` false) or
// of 1 − g (`other` true), T from the ray's origin, by vp.mis; its own random numbers. With
// several media μ is their sum and the two optical-depth estimates are sums over the media.
fn mis_weight(ray: MediaRay, t: f32, mu: f32, p0: f32, other: bool, rng: ptr<function, u32>) -> f32 {
    if vp.mis == MIS_MILLER {
        let w = mis_miller(mu, p0, ratio_tracking_to(ray, t, rng));
        return select(w, 1.0 - w, other);
    }
    let r = select(mis_free_flight(mu, p0), mis_other(mu, p0), other);
    // The naive weight is g(X0) of one estimate (m = 1, Fig. 12d); the jackknife needs two.
    let m = select(2u, 1u, vp.mis == MIS_NAIVE);
    var x = vec2f(0.0);
    for (var i = 0u; i < media_count(); i++) {
        let h = segment_in(i, ray.origin, ray.dir, min(t, ray.t_max));
        if h.t0 < h.t1 {
            let prep = od_prepare(h, true);
            od_estimate(h, prep, m, vp.samples, true, true, rng);
            x += vec2f(od_x[0], od_x[1]);
        }
    }
    if vp.mis == MIS_NAIVE {
        return mis_naive(r, x.x);
    }
    return mis_jackknife(r, x.x, x.y);
}

// Strategy 0 of Sec. 5.2 on the part `span` of the ray in the media: one equiangular sample per
// positional light, weighted as Eq. 9 (w̃0 T̃ σ_s L_s / p0, T̃ by ratio tracking) or Eq. 10
// (g̃ (σ_s / μ) L_s).
fn equiangular_lights(ray: MediaRay, span: vec2f, rng: ptr<function, u32>) -> vec3f {
    let origin = ray.origin;
    let dir = ray.dir;
    var sum = vec3f(0.0);
    for (var i = 0u; i < frame.analytic_lights; i++) {
        let l = light(i);
        if l.kind == LIGHT_DIRECTIONAL {
            continue;
        }
        let eq = equiangular_new(origin, dir, l.p0, span.x, span.y);
        let t = equiangular_sample(eq, rng_next(rng));
        let p0 = equiangular_pdf(eq, t);
        let ext = extinction_at(ray, t);
        let mu = ext.w;
        let ls = sample_analytic_light(l, origin + dir * t, rng_next2(rng));
        if mu <= 0.0 || max_component(ls.weight) <= 0.0 {
            continue;
        }
        let vis = visibility(origin + dir * t, ls.wi, ls.dist * (1.0 - 1.0e-4), rng);
        if vis <= 0.0 {
            continue;
        }
        // The albedo σ_s / μ of the media at t.
        let inscattered = (ext.xyz / mu) * INV_4PI * ls.weight * vis;
        if vp.eq10 != 0u {
            sum += mis_weight(ray, t, mu, p0, false, rng) * inscattered;
        } else {
            let w0 = mis_weight(ray, t, mu, p0, true, rng);
            var tr: f32;
            if vp.eq9_exact != 0u {
                tr = exact_transmittance_to(ray, t);
            } else {
                tr = ratio_tracking_to(ray, t, rng);
            }
            sum += (w0 * tr * mu / p0) * inscattered;
        }
    }
    return sum;
}

// Next-event estimation at v: every analytic light, one emissive triangle, the environment, as
// pt_integrator's next_event, with the shadow rays' transmittance. At a medium vertex reached by
// delta tracking at t on the ray, whose part in the media is `span` (with equiangular sampling
// on), a positional light's estimate is strategy 1 of Sec. 5.2 and weighted by w̃1(t) (Eq. 9
// and Eq. 10 alike).
fn next_event(v: Vertex, ray: MediaRay, span: vec2f, t: f32, rng: ptr<function, u32>) -> vec3f {
    var radiance = vec3f(0.0);
    for (var i = 0u; i < frame.analytic_lights; i++) {
        let l = light(i);
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
            let eq = equiangular_new(ray.origin, ray.dir, l.p0, span.x, span.y);
            w = mis_weight(ray, t, extinction_at(ray, t).w, equiangular_pdf(eq, t), false, rng);
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
        let ray = MediaRay(origin, dir, t_hit);
        let span = media_span(ray);
        var t_collision = BIG;
        var collided = 0u;
        if span.x < span.y {
            if vp.mis != MIS_NONE && depth < max_depth {
                radiance += throughput * equiangular_lights(ray, span, rng);
            }
            // The earliest collision over the media: medium i need only be tracked up to the
            // earliest found so far.
            for (var i = 0u; i < media_count(); i++) {
                let s = segment_in(i, origin, dir, min(t_hit, t_collision));
                if s.t0 < s.t1 {
                    let t = delta_tracking(s, rng);
                    if t < t_collision {
                        t_collision = t;
                        collided = i;
                    }
                }
            }
        }
        var v: Vertex;
        if t_collision < BIG {
            // Emission at the collision, before its scattering weight (ε per unit extinction).
            radiance += throughput * optics[2u * collided + 1u].xyz;
            if depth == max_depth {
                break;
            }
            v.p = origin + dir * t_collision;
            v.in_medium = true;
            v.wo = -dir;
            // Delta tracking's weight at a real collision: σ_s / σ_t.
            throughput *= optics[2u * collided].xyz;
            radiance += throughput * next_event(v, ray, span, t_collision, rng);
            dir = sample_uniform_sphere(rng_next2(rng));
            prev_pdf = INV_4PI;
        } else {
            if hit.instance == NO_HIT {
                radiance += throughput * escaped_radiance(dir, prev_pdf);
                break;
            }
            let sp = surface_point(hit, origin, dir);
            let m = material(sp.material);
            v.wo = -dir;
            v.sh = orient(sp, v.wo);
            v.in_medium = false;
            v.p = sp.position;
            radiance += throughput * emitted_radiance(sp, m, dir, hit.t, prev_pdf);
            if depth == max_depth {
                break;
            }
            v.bsdf = make_bsdf(base_color_at(m, sp.uv), m.metallic, m.roughness, m.specular);
            radiance += throughput * next_event(v, ray, span, 0.0, rng);
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
