//! Relative L2 loss of NRC: (f - y)^2 / (sg(f)^2 + ε), mean over the three channels (and, by the
//! caller, over the batch). sg = stop-gradient: the denominator is a constant for the gradient.

use super::real::Real;
use crate::config::{LossNormalization, LossSettings};

/// Rec. 709 luminance weights.
pub const LUMINANCE: [f32; 3] = [0.2126, 0.7152, 0.0722];

/// The denominators sg(f)^2 + ε per channel.
pub fn denominators<T: Real>(config: &LossSettings, f: [T; 3]) -> [T; 3] {
    let eps = T::from_f32(config.epsilon);
    match config.normalization {
        LossNormalization::PerChannel => [f[0] * f[0] + eps, f[1] * f[1] + eps, f[2] * f[2] + eps],
        LossNormalization::Luminance => {
            let l = T::from_f32(LUMINANCE[0]) * f[0]
                + T::from_f32(LUMINANCE[1]) * f[1]
                + T::from_f32(LUMINANCE[2]) * f[2];
            [l * l + eps; 3]
        }
    }
}

/// Loss of one record with the given denominators, and dL/df.
pub fn relative_l2<T: Real>(f: [T; 3], y: [T; 3], den: [T; 3]) -> (T, [T; 3]) {
    let mut loss = T::zero();
    let mut grad = [T::zero(); 3];
    for c in 0..3 {
        let diff = f[c] - y[c];
        loss += diff * diff / den[c];
        grad[c] = T::from_f32(2.0 / 3.0) * diff / den[c];
    }
    (loss / T::from_f32(3.0), grad)
}
