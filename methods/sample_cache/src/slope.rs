//! The slope test of adaptive retracing (section 3.4, eqs. 1 and 2 and appendix A), the CPU twin
//! of shaders/sample_cache/slope.wgsl.

/// Eq. 1: Δn = t |1 - cos θ / cos(θ - φ)|.
pub fn slope(t: f32, cos_theta: f32, phi: f32) -> f32 {
    let c = cos_theta.clamp(0.0, 1.0);
    let theta = c.acos();
    t * (1.0 - c / (theta - phi).cos()).abs()
}

/// Eq. 2: t_max < (1 + ε1)(t_min + 2 Δn).
pub fn consistent(t_min: f32, t_max: f32, slope: f32, epsilon1: f32) -> bool {
    t_max < (1.0 + epsilon1) * (t_min + 2.0 * slope)
}

/// φ: the angle subtended by a pixel's diagonal at the image centre.
pub fn pixel_diagonal_angle(vfov: f32, height: u32) -> f32 {
    let pixel = 2.0 * (0.5 * vfov).tan() / height as f32;
    (std::f32::consts::SQRT_2 * pixel).atan()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn flat_surface_passes_and_a_step_fails() {
        let phi = pixel_diagonal_angle(45f32.to_radians(), 36);
        // Fronto-parallel: no spread expected, neighbours a hair farther still pass (ε1).
        assert!(slope(2.0, 1.0, phi) < 2.0 * 1e-2);
        assert!(consistent(2.0, 2.0 * (1.0 + 2.0 * phi * phi), slope(2.0, 1.0, phi), 0.005));
        // Oblique at 80°: Δn grows with the incidence and covers the spread of the plane.
        let s = slope(2.0, 80f32.to_radians().cos(), phi);
        assert!(s > 0.1, "{s}");
        // A depth step of 10% is an edge.
        assert!(!consistent(2.0, 2.2, slope(2.0, 1.0, phi), 0.005));
    }
}
