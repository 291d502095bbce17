// Test kernels of media/tests/chi2_equiangular.rs: equiangular sampling (media_mis.wgsl, the
// volume path tracer's distance sampler towards a point light) drawn `count` times, and its pdf
// at given distances. A ray from the origin along +x, the light at (delta, d, 0), the part
// [a, b] of the ray: params[0] = (delta, d, a, b), params[1] = (count, seed, -, -) as u32 bits.

import package::pt_sampling::{rng_next, rng_seed};
import package::media::media_mis::{Equiangular, equiangular_new, equiangular_pdf, equiangular_sample};
import package::media::chi2_bindings::{params, points, result};

fn count() -> u32 {
    return bitcast<u32>(params[1].x);
}

fn sampler() -> Equiangular {
    let q = params[0];
    return equiangular_new(vec3f(0.0), vec3f(1.0, 0.0, 0.0), vec3f(q.x, q.y, 0.0), q.z, q.w);
}

@compute @workgroup_size(64)
fn equiangular_sample_main(@builtin(global_invocation_id) id: vec3u) {
    let i = id.x + id.y * 2097152u;
    if i >= count() {
        return;
    }
    var rng = rng_seed(vec2u(bitcast<u32>(params[1].y), 0u), 0u, i, 0u);
    result[i] = vec4f(equiangular_sample(sampler(), rng_next(&rng)), 0.0, 0.0, 0.0);
}

@compute @workgroup_size(64)
fn equiangular_pdf_main(@builtin(global_invocation_id) id: vec3u) {
    let i = id.x + id.y * 2097152u;
    if i >= count() {
        return;
    }
    result[i] = vec4f(equiangular_pdf(sampler(), points[i].x), 0.0, 0.0, 0.0);
}
