//! Intensity waveforms for lights and emissive meshes.

use bevy_ecs::prelude::*;

use crate::components::Intensity;
use crate::resources::{Clock, SimRng};
use crate::rng::hash_unit;

#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Waveform {
    /// I(t) = I0 (sin 2πft + 1): between 0 and twice the authored power.
    Sine { frequency: f32 },
    /// On for the first half of each period, off for the second.
    Square { period: f32 },
    /// Each frame on with probability `probability`, drawn from the scenario's seed.
    Strobe { probability: f32 },
}

impl Waveform {
    /// The multiplier at time `t` (seconds) of frame `frame`; `stream` separates strobes.
    pub fn value(&self, t: f32, frame: u32, seed: u64, stream: u64) -> f32 {
        match *self {
            Waveform::Sine { frequency } => (std::f32::consts::TAU * frequency * t).sin() + 1.0,
            Waveform::Square { period } => {
                // Frame time in units of the period; a tiny bias keeps exact half-periods
                // from flipping on rounding.
                let phase = (t / period + 1e-6).fract();
                if phase < 0.5 { 1.0 } else { 0.0 }
            }
            Waveform::Strobe { probability } => {
                if hash_unit(seed, stream, frame as u64) < probability { 1.0 } else { 0.0 }
            }
        }
    }
}

/// Drives an entity's [`Intensity`] scale.
#[derive(Component, Clone, Copy, Debug, PartialEq)]
pub struct Flash {
    pub waveform: Waveform,
    /// Random stream of this flash (its index in the scenario), so strobes differ.
    pub stream: u64,
}

pub fn flash(clock: Res<Clock>, rng: Res<SimRng>, mut query: Query<(&Flash, &mut Intensity)>) {
    for (f, mut intensity) in &mut query {
        let v = f.waveform.value(clock.time(), clock.frame, rng.seed, f.stream);
        if intensity.scale != v {
            intensity.scale = v;
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn sine_matches_formula_at_given_times() {
        let w = Waveform::Sine { frequency: 0.5 };
        // f = 0.5 Hz: t = 0 -> 1, t = 0.5 -> 2 (peak), t = 1 -> 1, t = 1.5 -> 0 (trough).
        for (t, expected) in [(0.0, 1.0), (0.5, 2.0), (1.0, 1.0), (1.5, 0.0)] {
            assert!((w.value(t, 0, 0, 0) - expected).abs() < 1e-5, "t={t}");
        }
    }

    #[test]
    fn square_toggles_each_half_period() {
        let w = Waveform::Square { period: 1.0 };
        let dt = 0.1;
        let values: Vec<f32> = (0..20).map(|f| w.value(f as f32 * dt, f, 0, 0)).collect();
        let expected: Vec<f32> =
            (0..20).map(|f| if (f / 5) % 2 == 0 { 1.0 } else { 0.0 }).collect();
        assert_eq!(values, expected);
    }

    #[test]
    fn strobe_is_seeded_and_has_its_duty() {
        let w = Waveform::Strobe { probability: 0.3 };
        let a: Vec<f32> = (0..1000).map(|f| w.value(0.0, f, 11, 0)).collect();
        let b: Vec<f32> = (0..1000).map(|f| w.value(0.0, f, 11, 0)).collect();
        let c: Vec<f32> = (0..1000).map(|f| w.value(0.0, f, 12, 0)).collect();
        assert_eq!(a, b);
        assert_ne!(a, c);
        let duty = a.iter().sum::<f32>() / 1000.0;
        assert!((duty - 0.3).abs() < 0.05, "duty {duty}");
    }
}
