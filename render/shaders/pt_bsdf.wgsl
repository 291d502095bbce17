// glTF metallic-roughness BSDF: Lambertian diffuse + GGX microfacet specular (Walter et al.
// 2007) with Smith height-correlated visibility (Heitz 2014) and Schlick Fresnel, combined as in
// the glTF 2.0 spec appendix B: f = (1 - F) c_diff / pi + F D V. KHR_materials_specular's factor
// scales the dielectric Fresnel (0 = pure Lambertian). All directions are world space, unit, and
// `n` is the shading normal turned towards `wo`.

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

fn ggx_d(alpha: f32, n_dot_h: f32) -> f32 {
    let a2 = alpha * alpha;
    let d = n_dot_h * n_dot_h * (a2 - 1.0) + 1.0;
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

fn bsdf_eval(b: Bsdf, n: vec3f, wo: vec3f, wi: vec3f) -> vec3f {
    let n_dot_v = dot(n, wo);
    let n_dot_l = dot(n, wi);
    if n_dot_v <= 0.0 || n_dot_l <= 0.0 {
        return vec3f(0.0);
    }
    let h = normalize(wo + wi);
    let v_dot_h = max(dot(wo, h), 0.0);
    let f = fresnel_schlick(b, v_dot_h);
    let specular = f * ggx_d(b.alpha, max(dot(n, h), 0.0)) * smith_visibility(b.alpha, n_dot_v, n_dot_l);
    return (vec3f(1.0) - f) * b.c_diff * INV_PI + specular;
}

// Solid-angle pdf of bsdf_sample choosing wi.
fn bsdf_pdf(b: Bsdf, n: vec3f, wo: vec3f, wi: vec3f) -> f32 {
    let n_dot_v = dot(n, wo);
    let n_dot_l = dot(n, wi);
    if n_dot_v <= 0.0 || n_dot_l <= 0.0 {
        return 0.0;
    }
    let p_spec = specular_probability(b, n_dot_v);
    let h = normalize(wo + wi);
    // Half-vector pdf D (n.h), mapped to wi by the reflection Jacobian 1 / (4 v.h).
    let pdf_spec = ggx_d(b.alpha, max(dot(n, h), 0.0)) * max(dot(n, h), 0.0) / max(4.0 * dot(wo, h), 1.0e-12);
    return p_spec * pdf_spec + (1.0 - p_spec) * n_dot_l * INV_PI;
}

fn bsdf_sample(b: Bsdf, n: vec3f, wo: vec3f, u_lobe: f32, u: vec2f) -> BsdfSample {
    var s: BsdfSample;
    s.valid = false;
    let n_dot_v = dot(n, wo);
    if n_dot_v <= 0.0 {
        return s;
    }
    let p_spec = specular_probability(b, n_dot_v);
    if u_lobe < p_spec {
        // GGX half vector from D (n.h): cos^2 theta_h = (1 - u) / (1 + (a^2 - 1) u).
        let a2 = b.alpha * b.alpha;
        let cos2 = (1.0 - u.x) / (1.0 + (a2 - 1.0) * u.x);
        let cos_h = sqrt(max(cos2, 0.0));
        let sin_h = sqrt(max(1.0 - cos2, 0.0));
        let phi = TWO_PI * u.y;
        let h = to_world(vec3f(sin_h * cos(phi), sin_h * sin(phi), cos_h), n);
        s.wi = reflect(-wo, h);
    } else {
        s.wi = to_world(sample_cosine_hemisphere(u), n);
    }
    s.pdf = bsdf_pdf(b, n, wo, s.wi);
    if s.pdf <= 0.0 {
        return s;
    }
    s.f = bsdf_eval(b, n, wo, s.wi);
    s.valid = true;
    return s;
}
