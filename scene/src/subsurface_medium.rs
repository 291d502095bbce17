//! The homogeneous medium a subsurface material stands for, for the random-walk ground truth:
//! extinction σ_t and single-scattering albedo α per channel from the material's surface albedo
//! A (its base colour) and diffuse mean free path ℓ_d.
//!
//! The mapping is Chiang, Kutz & Burley 2016 ("Practical and Controllable Subsurface Scattering
//! for Production Path Tracing", SIGGRAPH talk), fitted so that a random walk in an isotropic
//! medium reproduces Burley's profile of albedo A and shape d:
//!   α = 1 − exp(−5.09406 A + 2.61188 A² − 4.31805 A³),
//!   σ_t = 1 / (d s(A)), s(A) = 1.9 − A + 3.5 (A − 0.8)²
//! (s is Christensen & Burley 2015's searchlight fit with the volume mean free path ℓ = 1/σ_t as
//! parameter, d = ℓ / s). The d is the one the screen-space pass uses: d = ℓ_d / (3.5 + 100
//! (A − 0.33)⁴) (the thesis's Θ3, eq. 2.44), so the walk and the pass share A and d.

use glam::Vec3;

/// Single-scattering albedo and extinction per channel (per scene unit).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SubsurfaceMedium {
    pub sigma_t: Vec3,
    pub albedo: Vec3,
}

/// Chiang et al.'s single-scattering albedo α(A).
pub fn single_scattering_albedo(a: f64) -> f64 {
    1.0 - (a * (-5.09406 + a * (2.61188 - a * 4.31805))).exp()
}

/// Christensen & Burley's s(A) with the volume mean free path as parameter.
pub fn scaling_from_mfp(a: f64) -> f64 {
    1.9 - a + 3.5 * (a - 0.8) * (a - 0.8)
}

/// The thesis's Θ3: s(A) with the diffuse mean free path as parameter, d = ℓ_d / s.
pub fn scaling_from_dmfp(a: f64) -> f64 {
    3.5 + 100.0 * (a - 0.33).powi(4)
}

impl SubsurfaceMedium {
    /// The medium of surface albedo `albedo` (each channel in [0, 1]) and diffuse mean free path
    /// `dmfp` (each positive and finite); otherwise what was expected.
    pub fn from_albedo(albedo: Vec3, dmfp: Vec3) -> Result<Self, String> {
        if !(albedo.is_finite() && albedo.min_element() >= 0.0 && albedo.max_element() <= 1.0) {
            return Err(format!(
                "albedo ({}, {}, {}); expected each channel in [0, 1] for the random-walk medium",
                albedo.x, albedo.y, albedo.z
            ));
        }
        if !(dmfp.is_finite() && dmfp.min_element() > 0.0) {
            return Err(format!(
                "dmfp ({}, {}, {}); expected three positive finite diffuse mean free paths",
                dmfp.x, dmfp.y, dmfp.z
            ));
        }
        let channel = |a: f32, l: f32| {
            let a = f64::from(a);
            let d = f64::from(l) / scaling_from_dmfp(a);
            ((1.0 / (d * scaling_from_mfp(a))) as f32, single_scattering_albedo(a) as f32)
        };
        let [r, g, b] = [0, 1, 2].map(|c| channel(albedo[c], dmfp[c]));
        Ok(Self { sigma_t: Vec3::new(r.0, g.0, b.0), albedo: Vec3::new(r.1, g.1, b.1) })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_published_fits_at_hand_computed_points() {
        // A = 0: α = 0, s = 1.9 + 3.5·0.64 = 4.14; A = 1: α = 1 − e^{−6.80023}, s = 1.04.
        assert_eq!(single_scattering_albedo(0.0), 0.0);
        assert!((single_scattering_albedo(1.0) - (1.0 - (-6.80023f64).exp())).abs() < 1e-12);
        assert!((scaling_from_mfp(0.0) - 4.14).abs() < 1e-12);
        assert!((scaling_from_mfp(1.0) - 1.04).abs() < 1e-12);
        // A = 0.8, ℓ_d = 1: d = 1/(3.5 + 100·0.47⁴), σ_t = 1/(d·1.1).
        let m = SubsurfaceMedium::from_albedo(Vec3::splat(0.8), Vec3::ONE).unwrap();
        let d = 1.0 / (3.5 + 100.0 * 0.47f64.powi(4));
        assert!((f64::from(m.sigma_t.x) - 1.0 / (d * 1.1)).abs() < 1e-5);
        let alpha = 1.0 - (-5.09406 * 0.8 + 2.61188 * 0.64 - 4.31805 * 0.512f64).exp();
        assert!((f64::from(m.albedo.x) - alpha).abs() < 1e-6);
    }

    #[test]
    fn bad_albedo_or_dmfp_is_refused() {
        let ok = Vec3::splat(0.5);
        for a in
            [Vec3::new(1.1, 0.5, 0.5), Vec3::new(0.5, -0.1, 0.5), Vec3::new(0.5, 0.5, f32::NAN)]
        {
            assert!(SubsurfaceMedium::from_albedo(a, ok).unwrap_err().contains("[0, 1]"));
        }
        for d in [
            Vec3::new(0.0, 1.0, 1.0),
            Vec3::new(1.0, -1.0, 1.0),
            Vec3::new(1.0, 1.0, f32::INFINITY),
        ] {
            assert!(SubsurfaceMedium::from_albedo(ok, d).unwrap_err().contains("positive"));
        }
        assert!(SubsurfaceMedium::from_albedo(Vec3::ZERO, ok).is_ok());
        assert!(SubsurfaceMedium::from_albedo(Vec3::ONE, ok).is_ok());
    }
}
