// Test kernels of render/tests/chi2_sampling.rs: each sampling routine of the path tracer's
// library drawn `count` times (one draw per invocation, its own PCG stream), and its pdf
// evaluated at given directions, both through the library's own functions. A pass on the
// library: @group(0) and @group(1) are the scene's, @group(2) these buffers.
//
// params[0] = (wo, roughness), params[1] = (base colour, metallic), params[2] = (origin,
// specular), params[3] = (count, seed, light index, path) as u32 bits; path 1 calls the BSDF's
// general functions where the path_* kernels would call its public ones (Lambertian shortcut). Samples: result[i] =
// (direction, w) with w < 0 for an invalid draw; pdfs: result[i].x = pdf at points[i].xyz.

import package::scene_bindings::{frame};
import package::scene_tables::{light, material};
import package::scene_geometry::{NO_HIT, surface_point, trace_closest};
import package::pt_sampling::{luminance, rng_next, rng_next2, rng_seed, sample_uniform_sphere};
import package::pt_bsdf::{Bsdf, BsdfSample, bsdf_eval, bsdf_eval_general, bsdf_pdf, bsdf_pdf_general, bsdf_sample, bsdf_sample_general, make_bsdf};
import package::pt_lights::{FAR, directional_pdf, emitter_pdf, sample_analytic_light, sample_emitter};
import package::pt_scene::{environment_pdf};
import package::chi2_bindings::{params, points, result};

const N: vec3f = vec3f(0.0, 0.0, 1.0);
const ROW: u32 = 2097152u; // invocations per row of the dispatch (32768 workgroups of 64)

fn index(id: vec3u) -> u32 {
    return id.y * ROW + id.x;
}

fn count() -> u32 {
    return bitcast<u32>(params[3].x);
}

fn stream(i: u32) -> u32 {
    return rng_seed(vec2u(bitcast<u32>(params[3].y), 0u), 0u, i, 0u);
}

fn material_bsdf() -> Bsdf {
    return make_bsdf(params[1].xyz, params[1].w, params[0].w, params[2].w);
}

// wi from bsdf_sample around +z; w = f cos / pdf (the white furnace's estimate), < 0 if invalid.
@compute @workgroup_size(64)
fn bsdf_sample_main(@builtin(global_invocation_id) id: vec3u) {
    let i = index(id);
    if i >= count() {
        return;
    }
    var rng = stream(i);
    let u_lobe = rng_next(&rng);
    let s = bsdf_sample(material_bsdf(), N, params[0].xyz, u_lobe, rng_next2(&rng));
    if !s.valid {
        result[i] = vec4f(s.wi, -1.0);
        return;
    }
    result[i] = vec4f(s.wi, s.f.x * s.wi.z / s.pdf);
}

// x: bsdf_pdf(wo -> wi), y: f(wo, wi).x, z: f(wi, wo).x (reciprocity), wi = points[i].
@compute @workgroup_size(64)
fn bsdf_pdf_main(@builtin(global_invocation_id) id: vec3u) {
    let i = index(id);
    if i >= count() {
        return;
    }
    let b = material_bsdf();
    let wo = params[0].xyz;
    let wi = points[i].xyz;
    result[i] = vec4f(bsdf_pdf(b, N, wo, wi), bsdf_eval(b, N, wo, wi).x, bsdf_eval(b, N, wi, wo).x, 0.0);
}

// One emissive triangle chosen by power and a point on it, seen from params[2].xyz.
@compute @workgroup_size(64)
fn emitter_sample_main(@builtin(global_invocation_id) id: vec3u) {
    let i = index(id);
    if i >= count() {
        return;
    }
    var rng = stream(i);
    let u_select = rng_next(&rng);
    let s = sample_emitter(frame.analytic_lights, frame.emitters, params[2].xyz, u_select, rng_next2(&rng));
    result[i] = vec4f(s.wi, select(-1.0, s.pdf, s.pdf > 0.0));
}

// The pdf a BSDF-sampled ray's MIS weight gives the emitter it hits (emitted_radiance's).
@compute @workgroup_size(64)
fn emitter_pdf_main(@builtin(global_invocation_id) id: vec3u) {
    let i = index(id);
    if i >= count() {
        return;
    }
    let o = params[2].xyz;
    let d = points[i].xyz;
    let hit = trace_closest(o, d, FAR);
    var pdf = 0.0;
    if hit.instance != NO_HIT {
        let sp = surface_point(hit, o, d);
        let le_lum = luminance(material(sp.material).emission);
        let cos_light = -dot(sp.geometric_normal, d);
        if le_lum > 0.0 && cos_light > 0.0 {
            pdf = emitter_pdf(le_lum, cos_light, hit.t, frame.emitter_weight);
        }
    }
    result[i] = vec4f(pdf, 0.0, 0.0, 0.0);
}

// Analytic light params[3].z sampled from params[2].xyz (a directional light with a disk).
@compute @workgroup_size(64)
fn directional_sample_main(@builtin(global_invocation_id) id: vec3u) {
    let i = index(id);
    if i >= count() {
        return;
    }
    var rng = stream(i);
    let s = sample_analytic_light(light(bitcast<u32>(params[3].z)), params[2].xyz, rng_next2(&rng));
    result[i] = vec4f(s.wi, select(-1.0, s.pdf, s.pdf > 0.0));
}

@compute @workgroup_size(64)
fn directional_pdf_main(@builtin(global_invocation_id) id: vec3u) {
    let i = index(id);
    if i >= count() {
        return;
    }
    result[i] = vec4f(directional_pdf(light(bitcast<u32>(params[3].z)), points[i].xyz), 0.0, 0.0, 0.0);
}

// The environment's light sample (next_event_environment's draw) and its pdf.
@compute @workgroup_size(64)
fn environment_sample_main(@builtin(global_invocation_id) id: vec3u) {
    let i = index(id);
    if i >= count() {
        return;
    }
    var rng = stream(i);
    result[i] = vec4f(sample_uniform_sphere(rng_next2(&rng)), select(-1.0, 1.0, environment_pdf() > 0.0));
}

@compute @workgroup_size(64)
fn environment_pdf_main(@builtin(global_invocation_id) id: vec3u) {
    let i = index(id);
    if i >= count() {
        return;
    }
    result[i] = vec4f(environment_pdf(), 0.0, 0.0, 0.0);
}

// The public BSDF functions (path 0, with the Lambertian shortcut) or the general ones (path 1),
// after the same checks of the two directions' sides.
fn general_path() -> bool {
    return bitcast<u32>(params[3].w) == 1u;
}

fn path_sample(b: Bsdf, wo: vec3f, i: u32) -> BsdfSample {
    var rng = stream(i);
    let u_lobe = rng_next(&rng);
    let u = rng_next2(&rng);
    if !general_path() {
        return bsdf_sample(b, N, wo, u_lobe, u);
    }
    var s: BsdfSample;
    s.valid = false;
    if dot(N, wo) <= 0.0 {
        return s;
    }
    return bsdf_sample_general(b, N, wo, u_lobe, u, dot(N, wo));
}

// (pdf, f) of wo -> wi = points[i] through the chosen path.
@compute @workgroup_size(64)
fn path_eval_main(@builtin(global_invocation_id) id: vec3u) {
    let i = index(id);
    if i >= count() {
        return;
    }
    let b = material_bsdf();
    let wo = params[0].xyz;
    let wi = points[i].xyz;
    if !general_path() {
        result[i] = vec4f(bsdf_pdf(b, N, wo, wi), bsdf_eval(b, N, wo, wi));
        return;
    }
    let n_dot_v = dot(N, wo);
    let n_dot_l = dot(N, wi);
    if n_dot_v <= 0.0 || n_dot_l <= 0.0 {
        result[i] = vec4f(0.0);
        return;
    }
    result[i] = vec4f(bsdf_pdf_general(b, N, wo, wi, n_dot_v, n_dot_l), bsdf_eval_general(b, N, wo, wi, n_dot_v, n_dot_l));
}

// A draw's (wi, pdf) through the chosen path; pdf -1 for an invalid draw.
@compute @workgroup_size(64)
fn path_sample_main(@builtin(global_invocation_id) id: vec3u) {
    let i = index(id);
    if i >= count() {
        return;
    }
    let s = path_sample(material_bsdf(), params[0].xyz, i);
    result[i] = vec4f(s.wi, select(-1.0, s.pdf, s.valid));
}

// The same draw's (f, valid).
@compute @workgroup_size(64)
fn path_sample_value_main(@builtin(global_invocation_id) id: vec3u) {
    let i = index(id);
    if i >= count() {
        return;
    }
    let s = path_sample(material_bsdf(), params[0].xyz, i);
    result[i] = vec4f(s.f, select(0.0, 1.0, s.valid));
}
