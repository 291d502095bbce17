//! Contrast sensitivity filters of FLIP (Andersson et al. 2020, §3.1): in YCxCz, each channel is
//! convolved with a spatial filter whose frequency response models the eye's sensitivity at the
//! viewing distance. In the spatial domain each is a (sum of) Gaussian(s)
//!   S(x) = Σ_i a_i sqrt(π / b_i) exp(-π² x² / b_i),   x in degrees of visual angle,
//! normalised to unit sum. The Y and Cx filters are single Gaussians and so separable; the Cz filter
//! is a sum of two Gaussians, which is separated as two separable terms whose 1D factors carry the
//! square root of each 2D amplitude.

/// (a, b) pairs per channel: achromatic Y, red-green Cx, blue-yellow Cz (two Gaussians).
const Y_AB: (f32, f32) = (1.0, 0.0047);
const CX_AB: (f32, f32) = (1.0, 0.0053);
const CZ_AB: [(f32, f32); 2] = [(34.1, 0.04), (13.5, 0.025)];

/// 1D taps of the separated spatial filters, indexed from -radius to +radius.
#[derive(Clone, Debug)]
pub struct SpatialFilters {
    pub radius: usize,
    pub y: Vec<f32>,
    pub cx: Vec<f32>,
    /// The two 1D factors of the Cz filter; the 2D filter is cz1⊗cz1 + cz2⊗cz2.
    pub cz1: Vec<f32>,
    pub cz2: Vec<f32>,
}

/// Radius in pixels covering 3 standard deviations of the widest Gaussian (σ² = b / (2π²)).
pub fn spatial_radius(ppd: f32) -> usize {
    let pi2 = std::f32::consts::PI * std::f32::consts::PI;
    let b_max = [Y_AB.1, CX_AB.1, CZ_AB[0].1, CZ_AB[1].1].into_iter().fold(0.0f32, f32::max);
    (3.0 * (b_max / (2.0 * pi2)).sqrt() * ppd).ceil() as usize
}

impl SpatialFilters {
    pub fn new(ppd: f32) -> Self {
        let radius = spatial_radius(ppd);
        let pi = std::f32::consts::PI;
        let pi2 = pi * pi;
        let gauss = |x2: f32, a: f32, b: f32| a * (pi / b).sqrt() * (-pi2 * x2 / b).exp();
        let mut y = Vec::new();
        let mut cx = Vec::new();
        let mut cz1 = Vec::new();
        let mut cz2 = Vec::new();
        for i in 0..=2 * radius {
            // Tap offset in degrees.
            let d = (i as f32 - radius as f32) / ppd;
            let d2 = d * d;
            y.push(gauss(d2, Y_AB.0, Y_AB.1));
            cx.push(gauss(d2, CX_AB.0, CX_AB.1));
            // sqrt(a sqrt(π/b)) per axis, so the product of the two axes has amplitude a sqrt(π/b).
            cz1.push(
                gauss(d2, CZ_AB[0].0, CZ_AB[0].1) / (CZ_AB[0].0 * (pi / CZ_AB[0].1).sqrt()).sqrt(),
            );
            cz2.push(
                gauss(d2, CZ_AB[1].0, CZ_AB[1].1) / (CZ_AB[1].0 * (pi / CZ_AB[1].1).sqrt()).sqrt(),
            );
        }
        let normalise = |v: &mut Vec<f32>, s: f32| v.iter_mut().for_each(|w| *w /= s);
        let sy: f32 = y.iter().sum();
        let scx: f32 = cx.iter().sum();
        normalise(&mut y, sy);
        normalise(&mut cx, scx);
        // The 2D Cz filter sums to S1² + S2²: scale both factors so that this is 1.
        let s1: f32 = cz1.iter().sum();
        let s2: f32 = cz2.iter().sum();
        let s = (s1 * s1 + s2 * s2).sqrt();
        normalise(&mut cz1, s);
        normalise(&mut cz2, s);
        Self { radius, y, cx, cz1, cz2 }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn filters_sum_to_one_in_2d() {
        for ppd in [10.0, 30.0, 67.02] {
            let f = SpatialFilters::new(ppd);
            assert_eq!(f.y.len(), 2 * f.radius + 1);
            assert!((f.y.iter().sum::<f32>() - 1.0).abs() < 1e-5);
            assert!((f.cx.iter().sum::<f32>() - 1.0).abs() < 1e-5);
            let s1: f32 = f.cz1.iter().sum();
            let s2: f32 = f.cz2.iter().sum();
            assert!((s1 * s1 + s2 * s2 - 1.0).abs() < 1e-5);
            // Symmetric and peaked at the centre.
            assert_eq!(f.y[0], f.y[2 * f.radius]);
            assert!(f.y[f.radius] > f.y[f.radius + 1]);
        }
        // 3σ of the widest Gaussian (b = 0.04) at 67 ppd is about 9.05 pixels.
        assert_eq!(spatial_radius(67.02), 10);
    }
}
