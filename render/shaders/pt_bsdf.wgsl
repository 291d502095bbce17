// glTF metallic-roughness BSDF: Lambertian diffuse + GGX microfacet specular (Walter et al.
// 2007) with Smith height-correlated visibility (Heitz 2014) and Schlick Fresnel:
// f = c_diff / pi (1 - F(n.v)) (1 - F(n.l)) / (1 - F_avg) + F(v.h) D V.
// The diffuse part is coupled to the Fresnel of both directions as in Shirley et al. 1997 ("A
// practitioners' assessment of light reflection models"; F_avg = f0 + (f90 - f0) / 21 is
// Schlick's cosine-weighted hemispherical mean), not by the glTF 2.0 spec appendix B's
// (1 - F(v.h)): that weight lets a white dielectric reflect more than it receives at grazing
// views (albedo 1.84 at roughness 0.05 and 89 degrees; render/tests/chi2_sampling.rs's white
// furnace), because F(v.h) of a diffuse direction is far below the F(n.v) the specular lobe
// takes. The coupled form is reciprocal, and the diffuse albedo from n.v is exactly
// c_diff (1 - F(n.v)). KHR_materials_specular's factor scales the dielectric Fresnel
// (0 = pure Lambertian). All directions are world space, unit, and `n` is the shading normal
// turned towards `wo`.
//
// A Lambertian material (f0 = f90 = 0: metallic 0 and specular 0) takes a shortcut: with no
// Fresnel the coupling is exactly 1, the specular term and lobe probability exactly 0, so
// c_diff / pi and n.l / pi are the general formulas' own values, bit for bit, without their
// arithmetic (render/tests/chi2_sampling.rs compares the two paths). A scene without specular
// lobes compiles the general code out (HAS_SPECULAR false, render/src/scene_features.rs): lavapipe
// would otherwise run it under an empty mask.

import package::scene_features::{HAS_SPECULAR};
import package::pt_sampling::{INV_PI, PI, TWO_PI, basis_bitangent, basis_tangent, max_component, sample_cosine_hemisphere, to_world};

struct Bsdf {
    c_diff: vec3f,
    alpha: f32,
    f0: vec3f,
    f90: f32,
}

struct BsdfSample {
    wi: vec3f,
    pdf: f32,
    f: vec3f,
    valid: bool,
}

// Below this GGX alpha the lobe is a near-delta that float precision cannot sample or evaluate.
const MIN_ALPHA: f32 = 1.0e-3;

fn make_bsdf(base_color: vec3f, metallic: f32, roughness: f32, specular: f32) -> Bsdf {
    var b: Bsdf;
    let m = clamp(metallic, 0.0, 1.0);
    let r = clamp(roughness, 0.0, 1.0);
    b.c_diff = base_color * (1.0 - m);
    b.alpha = max(r * r, MIN_ALPHA);
    b.f0 = mix(vec3f(0.04 * max(specular, 0.0)), base_color, m);
    b.f90 = mix(max(specular, 0.0), 1.0, m);
    return b;
}

fn fresnel_schlick(b: Bsdf, cos_theta: f32) -> vec3f {
    let x = clamp(1.0 - cos_theta, 0.0, 1.0);
    let x2 = x * x;
    return b.f0 + (vec3f(b.f90) - b.f0) * (x2 * x2 * x);
}

// D(h) of the unit half vector h. (n.h)^2 (a^2 - 1) + 1 = sin^2 + a^2 cos^2 of h's angle, with
// sin^2 from h's part across n: 1 - (n.h)^2 in f32 loses most of its digits where a low
// roughness lobe lives (1 - n.h = 3e-6 at its peak at roughness 0.05), which made D 0.4% too
// high over that lobe (render/tests/chi2_sampling.rs, docs/lab/chi2-sampling.md).
fn ggx_d(alpha: f32, n: vec3f, h: vec3f) -> f32 {
    let a2 = alpha * alpha;
    let c = max(dot(n, h), 0.0);
    let across = h - c * n;
    let d = dot(across, across) + a2 * c * c;
    return a2 / (PI * d * d);
}

// Smith height-correlated visibility V = G2 / (4 |n.l| |n.v|).
fn smith_visibility(alpha: f32, n_dot_v: f32, n_dot_l: f32) -> f32 {
    let a2 = alpha * alpha;
    let gv = n_dot_l * sqrt(n_dot_v * n_dot_v * (1.0 - a2) + a2);
    let gl = n_dot_v * sqrt(n_dot_l * n_dot_l * (1.0 - a2) + a2);
    return 0.5 / max(gv + gl, 1.0e-12);
}

// Probability of sampling the specular lobe: its Fresnel weight against the remaining diffuse.
fn specular_probability(b: Bsdf, n_dot_v: f32) -> f32 {
    let fs = max_component(fresnel_schlick(b, n_dot_v));
    let fd = max_component(b.c_diff) * (1.0 - fs);
    if fs + fd <= 0.0 {
        return 0.0;
    }
    return fs / (fs + fd);
}

// True when the BSDF is exactly Lambertian: no Fresnel reflection at any angle; always in a
// scene without specular lobes.
fn is_lambertian(b: Bsdf) -> bool {
    return !HAS_SPECULAR || (all(b.f0 == vec3f(0.0)) && b.f90 == 0.0);
}

fn bsdf_eval(b: Bsdf, n: vec3f, wo: vec3f, wi: vec3f) -> vec3f {
    let n_dot_v = dot(n, wo);
    let n_dot_l = dot(n, wi);
    if n_dot_v <= 0.0 || n_dot_l <= 0.0 {
        return vec3f(0.0);
    }
    if is_lambertian(b) {
        return b.c_diff * INV_PI;
    }
    return bsdf_eval_general(b, n, wo, wi, n_dot_v, n_dot_l);
}

// bsdf_eval of any material, both directions above the surface.
fn bsdf_eval_general(b: Bsdf, n: vec3f, wo: vec3f, wi: vec3f, n_dot_v: f32, n_dot_l: f32) -> vec3f {
    let h = normalize(wo + wi);
    let v_dot_h = max(dot(wo, h), 0.0);
    let f = fresnel_schlick(b, v_dot_h);
    let specular = f * ggx_d(b.alpha, n, h) * smith_visibility(b.alpha, n_dot_v, n_dot_l);
    return diffuse_coupling(b, n_dot_v, n_dot_l) * b.c_diff * INV_PI + specular;
}

// (1 - F(n.v)) (1 - F(n.l)) / (1 - F_avg): the diffuse part's share of both directions
// (Shirley et al. 1997). Its cosine-weighted integral over n.l is 1 - F(n.v).
fn diffuse_coupling(b: Bsdf, n_dot_v: f32, n_dot_l: f32) -> vec3f {
    let f_avg = b.f0 + (vec3f(b.f90) - b.f0) * (1.0 / 21.0);
    let transmitted = (vec3f(1.0) - fresnel_schlick(b, n_dot_v)) * (vec3f(1.0) - fresnel_schlick(b, n_dot_l));
    return transmitted / max(vec3f(1.0) - f_avg, vec3f(1.0e-6));
}

// Solid-angle pdf of bsdf_sample choosing wi.
fn bsdf_pdf(b: Bsdf, n: vec3f, wo: vec3f, wi: vec3f) -> f32 {
    let n_dot_v = dot(n, wo);
    let n_dot_l = dot(n, wi);
    if n_dot_v <= 0.0 || n_dot_l <= 0.0 {
        return 0.0;
    }
    if is_lambertian(b) {
        return n_dot_l * INV_PI;
    }
    return bsdf_pdf_general(b, n, wo, wi, n_dot_v, n_dot_l);
}

// bsdf_pdf of any material, both directions above the surface.
fn bsdf_pdf_general(b: Bsdf, n: vec3f, wo: vec3f, wi: vec3f, n_dot_v: f32, n_dot_l: f32) -> f32 {
    let p_spec = specular_probability(b, n_dot_v);
    let h = normalize(wo + wi);
    // Visible-normal pdf G1(v) D(h) (v.h) / (n.v), mapped to wi by the reflection Jacobian
    // 1 / (4 v.h): G1(v) D(h) / (4 n.v) = D(h) / (2 (n.v + sqrt(a^2 + (1 - a^2)(n.v)^2))).
    let a2 = b.alpha * b.alpha;
    let pdf_spec = ggx_d(b.alpha, n, h) / (2.0 * (n_dot_v + sqrt(a2 + (1.0 - a2) * n_dot_v * n_dot_v)));
    return p_spec * pdf_spec + (1.0 - p_spec) * n_dot_l * INV_PI;
}

// A GGX normal visible from `wo` (local frame, +z the normal), distributed as
// G1(wo) max(0, wo.h) D(h) / wo.z: sampling visible normals keeps the specular sample weight
// F G2 / G1(wo) <= 1, where sampling D(h) cos alone gives weights that grow without bound at
// grazing angles (heavy-tailed noise). Spherical-cap method of Dupuy and Benyoub (2023):
// stretch wo to the alpha = 1 configuration, sample the cap of the unit sphere above -wo, and
// unstretch the result.
fn sample_ggx_visible_normal(wo: vec3f, alpha: f32, u: vec2f) -> vec3f {
    let v = normalize(vec3f(alpha * wo.x, alpha * wo.y, wo.z));
    let phi = TWO_PI * u.x;
    let z = (1.0 - u.y) * (1.0 + v.z) - v.z;
    let sin_theta = sqrt(clamp(1.0 - z * z, 0.0, 1.0));
    let h = vec3f(sin_theta * cos(phi), sin_theta * sin(phi), z) + v;
    return normalize(vec3f(alpha * h.x, alpha * h.y, max(h.z, 0.0)));
}

fn bsdf_sample(b: Bsdf, n: vec3f, wo: vec3f, u_lobe: f32, u: vec2f) -> BsdfSample {
    var s: BsdfSample;
    s.valid = false;
    let n_dot_v = dot(n, wo);
    if n_dot_v <= 0.0 {
        return s;
    }
    if is_lambertian(b) {
        // The general path with the lobe probability 0: the cosine hemisphere, its pdf and f.
        s.wi = to_world(sample_cosine_hemisphere(u), n);
        let n_dot_l = dot(n, s.wi);
        s.pdf = select(0.0, n_dot_l * INV_PI, n_dot_l > 0.0);
        if s.pdf <= 0.0 {
            return s;
        }
        s.f = b.c_diff * INV_PI;
        s.valid = true;
        return s;
    }
    return bsdf_sample_general(b, n, wo, u_lobe, u, n_dot_v);
}

// bsdf_sample of any material, wo above the surface (n.v > 0).
fn bsdf_sample_general(b: Bsdf, n: vec3f, wo: vec3f, u_lobe: f32, u: vec2f, n_dot_v: f32) -> BsdfSample {
    var s: BsdfSample;
    s.valid = false;
    let p_spec = specular_probability(b, n_dot_v);
    if u_lobe < p_spec {
        let t = basis_tangent(n);
        let bt = basis_bitangent(n);
        let wo_local = vec3f(dot(wo, t), dot(wo, bt), n_dot_v);
        let h = to_world(sample_ggx_visible_normal(wo_local, b.alpha, u), n);
        s.wi = reflect(-wo, h);
    } else {
        s.wi = to_world(sample_cosine_hemisphere(u), n);
    }
    let n_dot_l = dot(n, s.wi);
    if n_dot_l <= 0.0 {
        return s;
    }
    s.pdf = bsdf_pdf_general(b, n, wo, s.wi, n_dot_v, n_dot_l);
    if s.pdf <= 0.0 {
        return s;
    }
    s.f = bsdf_eval_general(b, n, wo, s.wi, n_dot_v, n_dot_l);
    s.valid = true;
    return s;
}
