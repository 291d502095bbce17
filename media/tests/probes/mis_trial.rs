//! One trial of the paper's MIS setting (Sec. 5.2) where everything but the weights is known in
//! closed form, so that Eqs. 9 and 10 can be checked against exact values: a homogeneous medium
//! μ on the ray segment [0, t_max] with a point light at distance D from the ray (foot point Δ),
//! in-scattered radiance L_s(t) = 1/(D² + (t − Δ)²) (isotropic phase and the light's own
//! transmittance folded into it), L_i = ∫₀^t_max μ e^{−μt} L_s(t) dt. Strategy 0 is equiangular
//! sampling, strategy 1 free-flight sampling (beyond t_max it hits the surface: L_s = 0).
//! Optical-depth estimates are synthetic normals N(μt, (σ_rel μt)²) (the jackknife's model); the
//! ratio-tracking estimates of Miller et al.'s weight track the homogeneous medium against a
//! majorant μ̂ > μ. The naive weight g(X0) reads one estimate (m = 1, as the paper's Fig. 12d;
//! its draws stay those of the pair, so every trial consumes the same numbers); the jackknife's
//! Re g(X̄ + iS) reads both. The WGSL twin is media/shaders/media_mis_trials.wgsl (same draws, same order).

use media::Pcg;
use media::equiangular::Equiangular;
use media::jackknife::jackknife;
use media::mis::{Ratio, eq9, eq10, miller_weight};

#[derive(Clone, Copy, Debug, PartialEq)]
pub struct MisSetup {
    pub mu: f32,
    pub majorant: f32,
    pub t_max: f32,
    pub delta: f32,
    pub d: f32,
    pub sigma_rel: f32,
}

impl MisSetup {
    pub fn equiangular(&self) -> Equiangular {
        Equiangular::from_foot(self.delta, self.d, 0.0, self.t_max)
    }

    pub fn ls(&self, t: f32) -> f32 {
        let x = t - self.delta;
        1.0 / (self.d * self.d + x * x)
    }
}

/// A trial's outputs. Weights of free-flight sampling at t1 per weight estimate, and the radiance
/// estimates: Eq. 9 per weight, Eq. 10 for the naive and jackknife g̃.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct MisTrial {
    /// Naive g(X0) (m = 1), jackknife Re g(X̄ + iS) (m = 2), Miller et al.'s.
    pub w1: [f32; 3],
    pub eq9: [f32; 3],
    pub eq10: [f32; 2],
}

impl MisTrial {
    pub fn values(&self) -> [f32; 8] {
        let (w, a, b) = (self.w1, self.eq9, self.eq10);
        [w[0], w[1], w[2], a[0], a[1], a[2], b[0], b[1]]
    }
}

/// A standard normal from two uniforms (Box–Muller, f32 like the WGSL).
pub fn normal_f32(rng: &mut Pcg) -> f32 {
    let u1 = 1.0 - rng.next_f32();
    let u2 = rng.next_f32();
    (-2.0 * u1.ln()).sqrt() * (std::f32::consts::TAU * u2).cos()
}

/// Two i.i.d. optical-depth estimates of τ with standard deviation σ_rel τ.
pub fn normal_pair(tau: f32, sigma_rel: f32, rng: &mut Pcg) -> (f32, f32) {
    let x0 = tau + sigma_rel * tau * normal_f32(rng);
    let x1 = tau + sigma_rel * tau * normal_f32(rng);
    (x0, x1)
}

/// Ratio tracking through a homogeneous medium μ of length `len` against majorant μ̂.
pub fn homogeneous_ratio_tracking(mu: f32, majorant: f32, len: f32, rng: &mut Pcg) -> f32 {
    let (mut t, mut tr) = (0.0, 1.0);
    loop {
        t += -(1.0 - rng.next_f32()).ln() / majorant;
        if t >= len {
            return tr;
        }
        tr *= 1.0 - mu / majorant;
    }
}

pub fn trial(s: &MisSetup, rng: &mut Pcg) -> MisTrial {
    let eq = s.equiangular();
    let t0 = eq.sample(rng.next_f32());
    let t1_free = -(1.0 - rng.next_f32()).ln() / s.mu;
    let inside = t1_free < s.t_max;
    // Beyond t_max the sample hits the surface; its weights are still drawn (at t_max) so that
    // every trial consumes the same numbers.
    let t1 = t1_free.min(s.t_max);
    let (p0_t0, p0_t1) = (eq.pdf(t0), eq.pdf(t1));
    let (ls0, ls1) = (s.ls(t0), if inside { s.ls(t1) } else { 0.0 });
    let a = normal_pair(s.mu * t0, s.sigma_rel, rng);
    let b = normal_pair(s.mu * t1, s.sigma_rel, rng);
    let c = normal_pair(s.mu * t0, s.sigma_rel, rng);
    let rt_w0 = homogeneous_ratio_tracking(s.mu, s.majorant, t0, rng);
    let rt_w1 = homogeneous_ratio_tracking(s.mu, s.majorant, t1, rng);
    let rt_t0 = homogeneous_ratio_tracking(s.mu, s.majorant, t0, rng);
    let (other, free) = (Ratio::other(s.mu, p0_t0), Ratio::free_flight(s.mu, p0_t1));
    let free_t0 = Ratio::free_flight(s.mu, p0_t0);
    let w0 = [other.naive(a.0), other.jackknife(a.0, a.1), 1.0 - miller_weight(s.mu, p0_t0, rt_w0)];
    let w1 = [free.naive(b.0), free.jackknife(b.0, b.1), miller_weight(s.mu, p0_t1, rt_w1)];
    // Eq. 9's independent unbiased T̃(t0): the jackknife (unbiased on normal inputs), ratio
    // tracking for Miller et al.
    let tr = [jackknife(c.0, c.1), jackknife(c.0, c.1), rt_t0];
    let eq9 = std::array::from_fn(|k| eq9(w0[k], tr[k], s.mu, p0_t0, ls0, w1[k], ls1));
    let eq10 = [
        eq10(free_t0.naive(a.0), ls0, w1[0], ls1),
        eq10(free_t0.jackknife(a.0, a.1), ls0, w1[1], ls1),
    ];
    MisTrial { w1, eq9, eq10 }
}
