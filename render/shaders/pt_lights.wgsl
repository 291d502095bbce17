// Light sampling for next-event estimation. One table holds the analytic lights followed by the
// emissive triangles (area lights); triangles are chosen by power (luminance x area) through the
// cumulative distribution in `cdf`, so the area pdf of any emissive point is luminance(Le) / W.
// Emissive triangles emit from their front face only (counter-clockwise winding), as pbrt's
// area lights do by default.

import package::scene_types::{GpuLight};
import package::scene_tables::{light, light_cdf};
import package::pt_sampling::{TWO_PI, sample_triangle, sample_uniform_cone, to_world};

const LIGHT_DIRECTIONAL: u32 = 0u;
const LIGHT_POINT: u32 = 1u;
const LIGHT_SPOT: u32 = 2u;
const LIGHT_TRIANGLE: u32 = 3u;

// Directional: p1 = direction into the scene, radiance = irradiance E on a facing surface,
//   a = 1 - cos(angular radius) (0: a delta light), b = 1 / (pi sin^2 r): disk radiance = E b.
// Point: p0 = position, radiance = intensity. Spot: p0 = position, p1 = axis, radiance =
//   intensity, a = cos(outer angle), b = cos(inner angle).
// Triangle: p0, p1, p2 = world vertices, radiance = emitted radiance, cdf = inclusive CDF.
struct LightSample {
    wi: vec3f,
    dist: f32,
    // Incident radiance divided by the sampling pdf (delta lights: the irradiance-like term).
    weight: vec3f,
    // Solid-angle pdf; 0 marks a delta light (no MIS).
    pdf: f32,
}

const FAR: f32 = 1.0e30;

fn spot_falloff(cos_axis: f32, cos_outer: f32, cos_inner: f32) -> f32 {
    if cos_inner <= cos_outer {
        return select(0.0, 1.0, cos_axis >= cos_outer);
    }
    let t = clamp((cos_axis - cos_outer) / (cos_inner - cos_outer), 0.0, 1.0);
    return t * t * (3.0 - 2.0 * t);
}

fn cone_solid_angle(one_minus_cos: f32) -> f32 {
    return TWO_PI * one_minus_cos;
}

// Solid-angle pdf with which sample_analytic_light picks `dir` from a directional light with an
// angular radius (uniform in its cone); 0 outside the cone and for every other light. A BSDF-
// sampled ray that escapes weighs the light's disk with it (pt_scene's escaped_radiance).
fn directional_pdf(l: GpuLight, dir: vec3f) -> f32 {
    if l.kind == LIGHT_DIRECTIONAL && l.a > 0.0 && 1.0 - dot(dir, -normalize(l.p1)) <= l.a {
        return 1.0 / cone_solid_angle(l.a);
    }
    return 0.0;
}

fn sample_analytic_light(l: GpuLight, p: vec3f, u: vec2f) -> LightSample {
    var s: LightSample;
    if l.kind == LIGHT_DIRECTIONAL {
        let axis = -normalize(l.p1);
        s.dist = FAR;
        if l.a > 0.0 {
            let local = sample_uniform_cone(u, 1.0 - l.a);
            s.wi = normalize(to_world(local, axis));
            s.pdf = 1.0 / cone_solid_angle(l.a);
            s.weight = l.radiance * l.b / s.pdf;
        } else {
            s.wi = axis;
            s.pdf = 0.0;
            s.weight = l.radiance;
        }
        return s;
    }
    let d = l.p0 - p;
    let dist2 = max(dot(d, d), 1.0e-20);
    s.dist = sqrt(dist2);
    s.wi = d / s.dist;
    s.pdf = 0.0;
    s.weight = l.radiance / dist2;
    if l.kind == LIGHT_SPOT {
        s.weight *= spot_falloff(dot(-s.wi, normalize(l.p1)), l.a, l.b);
    }
    return s;
}

// Solid-angle pdf with which sample_emitter picks the direction to an emissive point at distance
// `dist` whose luminance is `le_lum` and whose front face makes cosine `cos_light` (> 0) with the
// direction: luminance(Le) / W per unit area, W = `emitter_weight` (frame.emitter_weight),
// times dist^2 / cos. A BSDF-sampled ray that hits an emitter weighs it with this pdf
// (pt_integrator's emitted_radiance).
fn emitter_pdf(le_lum: f32, cos_light: f32, dist: f32, emitter_weight: f32) -> f32 {
    return le_lum / emitter_weight * dist * dist / cos_light;
}

// Index of the emissive triangle whose CDF interval holds u (binary search, <= 32 steps).
fn find_emitter(first: u32, count: u32, u: f32) -> u32 {
    var lo = first;
    var hi = first + count - 1u;
    while lo < hi {
        let mid = (lo + hi) / 2u;
        if light_cdf(mid) > u {
            hi = mid;
        } else {
            lo = mid + 1u;
        }
    }
    return lo;
}

fn sample_emitter(first: u32, count: u32, p: vec3f, u_select: f32, u: vec2f) -> LightSample {
    var s: LightSample;
    s.pdf = 0.0;
    s.weight = vec3f(0.0);
    let i = find_emitter(first, count, u_select);
    let l = light(i);
    var cdf_before = 0.0;
    if i > first {
        cdf_before = light_cdf(i - 1u);
    }
    let p_select = l.cdf - cdf_before;
    let b = sample_triangle(u);
    let x = b.x * l.p0 + b.y * l.p1 + (1.0 - b.x - b.y) * l.p2;
    let c = cross(l.p1 - l.p0, l.p2 - l.p0);
    let double_area = length(c);
    let d = x - p;
    let dist2 = dot(d, d);
    if p_select <= 0.0 || double_area <= 0.0 || dist2 <= 0.0 {
        return s;
    }
    s.dist = sqrt(dist2);
    s.wi = d / s.dist;
    // One-sided: the light emits from its front face (winding) only; wi points at the light.
    let cos_light = -dot(c / double_area, s.wi);
    if cos_light <= 0.0 {
        return s;
    }
    s.pdf = p_select / (0.5 * double_area) * dist2 / cos_light;
    s.weight = l.radiance / s.pdf;
    return s;
}
