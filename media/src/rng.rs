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
