// Test kernels of methods/sss/tests/chi2_burley.rs: the SSS pass's radius sampler
// (sampling.wgsl's sss_sample_radius, analytic inverse of Burley's radial cdf) drawn `count`
// times, and its pdf sss_radial_pdf at given radii. params[0] = (d, -, -, -), params[1] =
// (count, seed, fast inverse 0/1, -) as u32 bits.

import package::pt_sampling::{rng_next, rng_seed};
import package::sss::sampling::{sss_radial_pdf, sss_sample_radius};
import package::sss::chi2_bindings::{params, points, result};

fn count() -> u32 {
    return bitcast<u32>(params[1].x);
}

@compute @workgroup_size(64)
fn radius_sample_main(@builtin(global_invocation_id) id: vec3u) {
    let i = id.x + id.y * 2097152u;
    if i >= count() {
        return;
    }
    var rng = rng_seed(vec2u(bitcast<u32>(params[1].y), 0u), 0u, i, 0u);
    result[i] = vec4f(sss_sample_radius(rng_next(&rng), params[0].x, bitcast<u32>(params[1].z) != 0u), 0.0, 0.0, 0.0);
}

@compute @workgroup_size(64)
fn radius_pdf_main(@builtin(global_invocation_id) id: vec3u) {
    let i = id.x + id.y * 2097152u;
    if i >= count() {
        return;
    }
    result[i] = vec4f(sss_radial_pdf(points[i].x, params[0].x), 0.0, 0.0, 0.0);
}
