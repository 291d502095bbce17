// rand() of the media estimators: the path tracer's PCG stream (pt_sampling.wgsl's rng_next),
// restated here because the media passes compose without the scene library. The CPU reference
// media::rng::Pcg draws the same numbers bit for bit.
fn media_rand(state: ptr<function, u32>) -> f32 {
    *state = *state * 747796405u + 2891336453u;
    let s = *state;
    let word = ((s >> ((s >> 28u) + 4u)) ^ s) * 277803737u;
    return f32(((word >> 22u) ^ word) >> 8u) * (1.0 / 16777216.0);
}
