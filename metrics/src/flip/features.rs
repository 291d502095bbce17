//! Edge and point detection of FLIP (Andersson et al. 2020, §3.2): the achromatic channel,
//! normalised to [0, 1], is convolved with the first (edges) and second (points) derivatives of a
//! Gaussian of standard deviation σ = ½ w ppd, with w = 0.082° the width of a typical edge
//! detector cell. Derivatives are separable: d/dx of G(x)G(y) is G'(x)G(y), etc.

/// Width of the feature detectors in degrees.
pub const W: f32 = 0.082;

/// 1D taps, indexed from -radius to +radius.
#[derive(Clone, Debug)]
pub struct FeatureFilters {
    pub radius: usize,
    /// Gaussian, sums to 1.
    pub g: Vec<f32>,
    /// First derivative; positive taps sum to 1 and negative ones to -1.
    pub dg: Vec<f32>,
    /// Second derivative; same normalisation.
    pub ddg: Vec<f32>,
}

impl FeatureFilters {
    pub fn new(ppd: f32) -> Self {
        let sigma = 0.5 * W * ppd;
        let radius = (3.0 * sigma).ceil() as usize;
        let mut g = Vec::new();
        let mut dg = Vec::new();
        let mut ddg = Vec::new();
        for i in 0..=2 * radius {
            let x = i as f32 - radius as f32;
            let gx = (-(x * x) / (2.0 * sigma * sigma)).exp();
            g.push(gx);
            // Unnormalised derivatives (constant factors cancel in the normalisation below).
            dg.push(-x * gx);
            ddg.push((x * x / (sigma * sigma) - 1.0) * gx);
        }
        let sum_g: f32 = g.iter().sum();
        g.iter_mut().for_each(|v| *v /= sum_g);
        for taps in [&mut dg, &mut ddg] {
            let pos: f32 = taps.iter().filter(|v| **v > 0.0).sum();
            let neg: f32 = -taps.iter().filter(|v| **v <= 0.0).sum::<f32>();
            taps.iter_mut().for_each(|v| *v /= if *v > 0.0 { pos } else { neg });
        }
        Self { radius, g, dg, ddg }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn normalisation() {
        let f = FeatureFilters::new(67.02);
        assert_eq!(f.radius, 9); // 3σ = 3 * 2.748
        assert!((f.g.iter().sum::<f32>() - 1.0).abs() < 1e-5);
        for taps in [&f.dg, &f.ddg] {
            let pos: f32 = taps.iter().filter(|v| **v > 0.0).sum();
            let neg: f32 = taps.iter().filter(|v| **v < 0.0).sum();
            assert!((pos - 1.0).abs() < 1e-5 && (neg + 1.0).abs() < 1e-5);
        }
        // A ramp has a constant first derivative response and zero second derivative response.
        let ramp: Vec<f32> = (0..f.dg.len()).map(|i| i as f32).collect();
        let d: f32 = f.dg.iter().zip(&ramp).map(|(a, b)| a * b).sum();
        let dd: f32 = f.ddg.iter().zip(&ramp).map(|(a, b)| a * b).sum();
        assert!(d < 0.0 && dd.abs() < 1e-4, "{d} {dd}");
    }
}
