//! The closed-form setting of the paper's Sec. 3 (Figs. 2 and 3), the twin of
//! closed_form_trials.wgsl beside this file: two synthetic optical-depth estimates
//! X_j = τ + σ e_j, e_j i.i.d. with mean 0 and variance 1 from a normal or one of Fig. 2's other
//! distributions, and per trial the jackknife K (Eq. 4) and the naive exp(−X̄). In f32 with the
//! WGSL's operations, so that the GPU's trials equal these to rounding.

use media::Pcg;
use media::jackknife::jackknife;

/// The distribution of the estimates' error e (all with variance 1).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[repr(u32)]
pub enum ErrorDistribution {
    Normal = 0,
    /// Uniform on [−√3, √3].
    Uniform = 1,
    /// Laplace of scale 1/√2.
    Laplace = 2,
    /// Single-sided: E − 1, E ~ Exp(1).
    Exponential = 3,
}

impl ErrorDistribution {
    pub fn sample(self, rng: &mut Pcg) -> f32 {
        match self {
            ErrorDistribution::Normal => {
                let u1 = 1.0 - rng.next_f32(); // (0, 1]
                let u2 = rng.next_f32();
                (-2.0 * u1.ln()).sqrt() * (std::f32::consts::TAU * u2).cos()
            }
            ErrorDistribution::Uniform => 3f32.sqrt() * (2.0 * rng.next_f32() - 1.0),
            ErrorDistribution::Laplace => {
                // u = v + 2^−25 − 0.5 on the open interval; 1 − 2|u| exactly, never 0.
                let v = rng.next_f32();
                let (sign, w) = if v >= 0.5 {
                    (1.0, 2.0 * (1.0 - v) - 2f32.powi(-24))
                } else {
                    (-1.0, 2.0 * v + 2f32.powi(-24))
                };
                -std::f32::consts::FRAC_1_SQRT_2 * sign * w.ln()
            }
            ErrorDistribution::Exponential => -(1.0 - rng.next_f32()).ln() - 1.0,
        }
    }
}

/// One trial: (K, exp(−X̄)) of X_j = τ + σ e_j, e_0 drawn before e_1.
pub fn trial(dist: ErrorDistribution, tau: f32, sigma: f32, rng: &mut Pcg) -> (f32, f32) {
    let x0 = tau + sigma * dist.sample(rng);
    let x1 = tau + sigma * dist.sample(rng);
    (jackknife(x0, x1), (-(0.5 * (x0 + x1))).exp())
}
