// Chromatic free flights of the subsurface random walk (media_subsurface_path.wgsl): one
// channel's extinction draws the distance, the channel chosen with probabilities q (the
// throughput's share per channel), so the distance's density is the mixture over the three
// channels (one-sample MIS with the balance heuristic, Chiang, Kutz & Burley 2016). The walk
// divides by these functions' pdf and survival; media/tests/chi2_free_flight.rs tests the draw
// against them.

// The channel probabilities of throughput `beta` (its share per channel); zero when beta is.
fn channel_probabilities(beta: vec3f) -> vec3f {
    let total = beta.x + beta.y + beta.z;
    if total <= 0.0 {
        return vec3f(0.0);
    }
    return beta / total;
}

// A distance Exp(sigma_t[c]) with the channel c drawn from q by u_channel.
fn sample_free_flight(sigma_t: vec3f, q: vec3f, u_channel: f32, u_distance: f32) -> f32 {
    let c = select(select(2u, 1u, u_channel < q.x + q.y), 0u, u_channel < q.x);
    return -log(1.0 - u_distance) / sigma_t[c];
}

// The density of sample_free_flight's distance t: sum over channels of q σ_t e^{−σ_t t}.
fn free_flight_pdf(sigma_t: vec3f, q: vec3f, t: f32) -> f32 {
    return dot(q, sigma_t * exp(-sigma_t * t));
}

// The probability that the distance exceeds t: sum over channels of q e^{−σ_t t}.
fn free_flight_survival(sigma_t: vec3f, q: vec3f, t: f32) -> f32 {
    return dot(q, exp(-sigma_t * t));
}
