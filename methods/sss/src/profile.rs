//! Burley's normalized diffuse reflectance profile (thesis eq. 2.43, Christensen and Burley 2015):
//! R(r) = A (e^{-r/d} + e^{-r/(3d)}) / (8π d r), with ∫ R(r) 2πr dr = A.

use std::f64::consts::PI;

/// One channel's profile: surface albedo A and shape parameter d (scene units or pixels).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct BurleyProfile {
    pub albedo: f64,
    pub d: f64,
}

/// Θ3 of eq. 2.44 (diffuse mean free path ℓ_d on the surface as parameter): s = 3.5 + 100 (A − 0.33)^4,
/// d = ℓ_d / s. The thesis picks Θ3 as the artist-friendly parameterisation.
pub fn scaling_from_dmfp(albedo: f64) -> f64 {
    3.5 + 100.0 * (albedo - 0.33).powi(4)
}

impl BurleyProfile {
    /// The profile of a material with diffuse mean free path `dmfp` and albedo A (Θ3).
    pub fn from_dmfp(albedo: f64, dmfp: f64) -> Self {
        Self { albedo, d: dmfp / scaling_from_dmfp(albedo) }
    }

    /// R(r), eq. 2.43 (singular at r = 0; the sampler works with the radial density instead).
    pub fn reflectance(&self, r: f64) -> f64 {
        self.albedo * ((-r / self.d).exp() + (-r / (3.0 * self.d)).exp()) / (8.0 * PI * self.d * r)
    }

    /// The radial density 2πr R(r) / A = (e^{-r/d} + e^{-r/(3d)}) / (4d), which integrates to 1.
    pub fn radial_pdf(&self, r: f64) -> f64 {
        radial_pdf(r, self.d)
    }

    /// The cdf of the radial density, eq. 5.3.
    pub fn cdf(&self, r: f64) -> f64 {
        cdf(r, self.d)
    }
}

/// (e^{-r/d} + e^{-r/(3d)}) / (4d).
pub fn radial_pdf(r: f64, d: f64) -> f64 {
    ((-r / d).exp() + (-r / (3.0 * d)).exp()) / (4.0 * d)
}

/// 1 − e^{−r/d}/4 − 3e^{−r/(3d)}/4 (eq. 5.3).
pub fn cdf(r: f64, d: f64) -> f64 {
    1.0 - 0.25 * (-r / d).exp() - 0.75 * (-r / (3.0 * d)).exp()
}
