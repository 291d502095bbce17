// Test kernel of media/tests/chi2_free_flight.rs: the subsurface walk's chromatic free flight
// (media_free_flight.wgsl) drawn `count` times as the walk draws it (channel, then distance, from
// the path tracer's PCG stream), and its pdf and survival at given distances.
// params[0] = (σ_t, -), params[1] = (throughput, -), params[2] = (count, seed, -, -) as u32 bits.
// Draws: result[i].x = t. Pdfs: result[i] = (pdf, survival, -, -) at t = points[i].x.

import package::pt_sampling::{rng_next, rng_seed};
import package::media::media_free_flight::{channel_probabilities, free_flight_pdf, free_flight_survival, sample_free_flight};
import package::media::chi2_bindings::{params, points, result};

const ROW: u32 = 2097152u; // invocations per row of the dispatch (32768 workgroups of 64)

fn count() -> u32 {
    return bitcast<u32>(params[2].x);
}

@compute @workgroup_size(64)
fn free_flight_sample_main(@builtin(global_invocation_id) id: vec3u) {
    let i = id.x + id.y * ROW;
    if i >= count() {
        return;
    }
    var rng = rng_seed(vec2u(bitcast<u32>(params[2].y), 0u), 0u, i, 0u);
    let q = channel_probabilities(params[1].xyz);
    let u = rng_next(&rng);
    result[i] = vec4f(sample_free_flight(params[0].xyz, q, u, rng_next(&rng)), 0.0, 0.0, 0.0);
}

@compute @workgroup_size(64)
fn free_flight_pdf_main(@builtin(global_invocation_id) id: vec3u) {
    let i = id.x + id.y * ROW;
    if i >= count() {
        return;
    }
    let q = channel_probabilities(params[1].xyz);
    let t = points[i].x;
    result[i] = vec4f(free_flight_pdf(params[0].xyz, q, t), free_flight_survival(params[0].xyz, q, t), 0.0, 0.0);
}
