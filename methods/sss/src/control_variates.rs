//! Control variates in the sample-count domain (thesis Ch. 6): the exponential moving covariance
//! (EMC, eq. 6.16) of the pixel's scattered value f̄ and its in-frame constant control G(t)
//! (the centre irradiance, eq. 6.14), and the coefficient a_t = (Cov + ε_a)/(Var + ε_a)
//! (eq. 6.21) clamped to D = [0, a0 + f̄/ḡ] (Sec. 6.5.4). f32, as shaders/spvg.wgsl.

/// J_t of one pixel: ζ = EMA of (f̄, ḡ), Cov(f̄, ḡ), Var(ḡ) (Σ.xx is never read, Sec. 6.5.5).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct EmCovariance {
    pub mean_f: f32,
    pub mean_g: f32,
    pub cov_fg: f32,
    pub var_g: f32,
}

impl EmCovariance {
    /// The first observation: ζ_0 = Z_0, Σ_0 = 0.
    pub fn start(f: f32, g: f32) -> Self {
        Self { mean_f: f, mean_g: g, cov_fg: 0.0, var_g: 0.0 }
    }

    /// Eq. 6.16/6.17 then ζ_t = (1 − α) ζ_{t−1} + α Z_t (Algorithm 5, lines 5-7).
    pub fn update(&self, alpha: f32, f: f32, g: f32) -> Self {
        let (df, dg) = (f - self.mean_f, g - self.mean_g);
        Self {
            mean_f: (1.0 - alpha) * self.mean_f + alpha * f,
            mean_g: (1.0 - alpha) * self.mean_g + alpha * g,
            cov_fg: (1.0 - alpha) * self.cov_fg + alpha * (1.0 - alpha) * df * dg,
            var_g: (1.0 - alpha) * self.var_g + alpha * (1.0 - alpha) * dg * dg,
        }
    }

    /// a = (Cov + ε_a)/(Var + ε_a) (eq. 6.21), clamped to D = [0, a0 + f̄/ḡ] (Algorithm 4).
    pub fn coefficient(&self, eps_a: f32, a0: f32, f: f32, g: f32) -> f32 {
        let a = (self.cov_fg + eps_a) / (self.var_g + eps_a);
        let upper = if g > 0.0 { a0 + f / g } else { a0 };
        a.clamp(0.0, upper)
    }
}

/// The variance-minimising coefficient of ⟨F⟩ − a(⟨G⟩ − G) (eq. 2.18): a* = Cov(F, G)/Var(G).
/// The thesis prints Var(F) in the denominator below eq. 2.18; d/da of eq. 2.18 is
/// 2a Var(G) − 2 Cov(F, G), so it is Var(G).
pub fn optimal_coefficient(cov_fg: f64, var_g: f64) -> f64 {
    cov_fg / var_g
}
