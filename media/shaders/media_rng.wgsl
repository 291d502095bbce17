// rand() of the media estimators: the path tracer's PCG stream (pt_sampling.wgsl's rng_next),
// restated here because the media passes compose without the scene library. The CPU reference
// media::rng::Pcg draws the same numbers bit for bit.

fn media_rand(state: ptr<function, u32>) -> f32 {
    *state = *state * 747796405u + 2891336453u;
    let s = *state;
    let word = ((s >> ((s >> 28u) + 4u)) ^ s) * 277803737u;
    return f32(((word >> 22u) ^ word) >> 8u) * (1.0 / 16777216.0);
}

// media::rng::image_seed.
fn media_image_seed(seed: u32, frame: u32, pixel: u32, sample: u32) -> u32 {
    return (seed ^ (frame * 0x9e3779b9u)) + pixel * 0x85ebca6bu + sample * 0xc2b2ae35u;
}
