//! MIS weights for distance sampling (paper Sec. 5.2): the balance-heuristic weight of
//! free-flight sampling against a strategy of known density p0 (equiangular sampling of a point
//! light), g(τ) = (u0 e^−τ + u1) / (v0 e^−τ + v1) (Eq. 11; u0 = v0 = μ(t), u1 = 0, v1 = p0(t)
//! for w1), estimated three ways, and the two radiance estimates that use them (Eqs. 9, 10).

/// The coefficients of Eq. 11.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Ratio {
    pub u0: f32,
    pub u1: f32,
    pub v0: f32,
    pub v1: f32,
}

impl Ratio {
    /// w1 = T μ / (p0 + T μ): the weight of free-flight sampling.
    pub fn free_flight(mu: f32, p0: f32) -> Self {
        Self { u0: mu, u1: 0.0, v0: mu, v1: p0 }
    }

    /// w0 = p0 / (p0 + T μ): the weight of the other strategy.
    pub fn other(mu: f32, p0: f32) -> Self {
        Self { u0: 0.0, u1: p0, v0: mu, v1: p0 }
    }

    /// The naive estimate g(X̄).
    pub fn naive(&self, x_mean: f32) -> f32 {
        let e = (-x_mean).exp();
        (self.u0 * e + self.u1) / (self.v0 * e + self.v1)
    }

    /// The jackknife estimate Re g(X̄ + iS) from two optical depths (Eq. 12), in Appendix F's
    /// real arithmetic: Re(U/V) = (Re U Re V + Im U Im V) / ((Re V)² + (Im V)²).
    pub fn jackknife(&self, x0: f32, x1: f32) -> f32 {
        let mean = 0.5 * (x0 + x1);
        let s = 0.5 * (x0 - x1).abs();
        let e = (-mean).exp();
        let (re, im) = (s.cos() * e, -s.sin() * e);
        let (re_u, im_u) = (self.u0 * re + self.u1, self.u0 * im);
        let (re_v, im_v) = (self.v0 * re + self.v1, self.v0 * im);
        (re_u * re_v + im_u * im_v) / (re_v * re_v + im_v * im_v)
    }
}

/// Miller et al. 2019's weight of free-flight sampling with the balance heuristic, as the
/// paper reduces it: μ T_rt / (p0 + μ T_rt), T_rt a ratio-tracking estimate.
pub fn miller_weight(mu: f32, p0: f32, t_ratio_tracking: f32) -> f32 {
    mu * t_ratio_tracking / (p0 + mu * t_ratio_tracking)
}

/// Eq. 9 (unbiased for any weight estimates whose expectations sum to 1): the sample t0 of the
/// other strategy weighted by w̃0 with an independent unbiased transmittance estimate T̃(t0),
/// the free-flight sample t1 by w̃1 (its T μ / p1 cancelled).
pub fn eq9(
    w0: f32,
    transmittance_t0: f32,
    mu_t0: f32,
    p0_t0: f32,
    ls0: f32,
    w1: f32,
    ls1: f32,
) -> f32 {
    w0 * transmittance_t0 * mu_t0 * ls0 / p0_t0 + w1 * ls1
}

/// Eq. 10 (slightly biased; no separate transmittance estimate): both samples weighted by an
/// estimate of g = T μ / (p0 + T μ) at their own distance.
pub fn eq10(g_t0: f32, ls0: f32, g_t1: f32, ls1: f32) -> f32 {
    g_t0 * ls0 + g_t1 * ls1
}
