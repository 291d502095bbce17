//! The random numbers every estimator draws: the path tracer's PCG stream (`rng_next` in
//! render/shaders/pt_sampling.wgsl, Jarzynski & Olano 2020), bit for bit, so that a WGSL
//! estimator fed the same seed draws the same numbers as this CPU reference. The paper also
//! uses PCG for `rand()` in Alg. 1.

#[derive(Clone, Copy, Debug)]
pub struct Pcg {
    pub state: u32,
}

impl Pcg {
    pub fn new(seed: u32) -> Self {
        Self { state: seed }
    }

    /// Uniform in [0, 1): the 24 high bits of the next PCG output.
    pub fn next_f32(&mut self) -> f32 {
        self.state = self.state.wrapping_mul(747796405).wrapping_add(2891336453);
        let s = self.state;
        let word = ((s >> ((s >> 28) + 4)) ^ s).wrapping_mul(277803737);
        (((word >> 22) ^ word) >> 8) as f32 * (1.0 / 16777216.0)
    }
}

/// A standard normal sample in f64 (Box–Muller on two PCG uniforms).
pub fn normal_f64(rng: &mut Pcg) -> f64 {
    let u1 = 1.0 - f64::from(rng.next_f32()); // (0, 1]
    let u2 = f64::from(rng.next_f32());
    (-2.0 * u1.ln()).sqrt() * (std::f64::consts::TAU * u2).cos()
}

/// The stream of one estimate of an image: (seed, frame, pixel, sample) spread by odd
/// multipliers (golden ratio and MurmurHash3's constants); the first PCG step mixes them.
pub fn image_seed(seed: u32, frame: u32, pixel: u32, sample: u32) -> u32 {
    (seed ^ frame.wrapping_mul(0x9e37_79b9))
        .wrapping_add(pixel.wrapping_mul(0x85eb_ca6b))
        .wrapping_add(sample.wrapping_mul(0xc2b2_ae35))
}
