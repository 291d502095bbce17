//! The slope test of adaptive retracing (section 3.4, eqs. 1 and 2 and appendix A), the CPU twin
//! of shaders/slope.wgsl.

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

/// A visible sample in the slope test: its depth t and its Δn (eq. 1).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Closest {
    pub t: f32,
    pub slope: f32,
}

impl Closest {
    /// A pixel with no visible sample (`SSC_NO_DEPTH`): never the closest of a neighbourhood.
    pub const NONE: Closest = Closest { t: 3.0e38, slope: 0.0 };

    /// Nearer first; on a tie the smaller Δn (the stricter test), whatever the slot order.
    pub fn closer(self, other: Closest) -> bool {
        self.t < other.t || (self.t == other.t && self.slope < other.slope)
    }

    /// The closest of `samples` (`NONE` when empty).
    pub fn of(samples: impl IntoIterator<Item = Closest>) -> Closest {
        samples.into_iter().fold(Closest::NONE, |a, b| if b.closer(a) { b } else { a })
    }
}

/// Section 3.4 over a pixel's 3x3 neighbourhood: eq. 2 between the pixel and each neighbour,
/// both ways. `centre` and each of `neighbourhood` (the 3x3 pixels, the centre among them) are a
/// pixel's closest visible sample and its farthest visible depth. The centre's closest against a
/// neighbour's farthest flags the raised side of a depth edge, a neighbour's closest against the
/// centre's farthest its far side. Each pair is at most two pixel diagonals apart, the span of
/// App. A's 2Δn, so a plane flags nothing.
pub fn flagged(
    centre: (Closest, f32),
    neighbourhood: impl IntoIterator<Item = (Closest, f32)>,
    epsilon1: f32,
) -> bool {
    let (own, own_far) = centre;
    neighbourhood.into_iter().any(|(c, far)| {
        !consistent(own.t, far, own.slope, epsilon1) || !consistent(c.t, own_far, c.slope, epsilon1)
    })
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

    #[test]
    fn both_sides_of_a_depth_step_are_flagged() {
        let phi = pixel_diagonal_angle(45f32.to_radians(), 36);
        let at = |t: f32| (Closest { t, slope: slope(t, 1.0, phi) }, t);
        let none = (Closest::NONE, 0.0);
        // A far pixel (2.2) beside a raised one (2.0): flagged on either side.
        assert!(flagged(at(2.0), [at(2.0), at(2.2)], 0.005));
        assert!(flagged(at(2.2), [at(2.2), at(2.0), none], 0.005));
        // A flat neighbourhood, and neighbours without visible samples, are not.
        assert!(!flagged(at(2.0), [at(2.0), at(2.0), none], 0.005));
        // Ties keep the smaller Δn, whatever the order.
        let (a, b) = (Closest { t: 2.0, slope: 0.1 }, Closest { t: 2.0, slope: 0.2 });
        assert_eq!(Closest::of([a, b]), a);
        assert_eq!(Closest::of([b, a]), a);
        assert_eq!(Closest::of([]), Closest::NONE);
    }
}
