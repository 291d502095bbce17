//! The transmittance estimators a method selects, by name, with their settings.

use serde::{Deserialize, Serialize};

use crate::jackknife::{JackknifeSettings, jackknife_transmittance, jackknife_transmittance_with};
use crate::medium::{Estimate, Medium, Segment};
use crate::optical_depth::SampleCount;
use crate::ratio_tracking::ratio_tracking;
use crate::ray_marching::{biased_ray_marching, naive};
use crate::rng::Pcg;
use crate::track_length::track_length;
use crate::unbiased_ray_marching::unbiased_ray_marching;

#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub enum Estimator {
    TrackLength,
    RatioTracking,
    /// Kettunen et al.'s exp(−X), their sample count times `multiplier`.
    BiasedRayMarching {
        multiplier: f32,
    },
    /// Kettunen et al.'s power series (degree ≤ 8), their sample count times `multiplier`.
    UnbiasedRayMarching {
        multiplier: f32,
    },
    /// exp(−X) of one estimate with `samples` = mN samples (paper's optical-depth estimator).
    Naive {
        samples: u32,
    },
    /// Eq. 4 from m = 2 estimates of `samples` = N samples each.
    Jackknife {
        samples: u32,
    },
    /// Eq. 4 from m = 2 estimates whose N is tied to the importance along the ray (Fig. 8d):
    /// N = ceil(F / `step`) in [1, 64], F the integral of importance (Alg. 2).
    JackknifeTied {
        step: f32,
    },
}

impl Estimator {
    pub fn label(&self) -> &'static str {
        match self {
            Estimator::TrackLength => "track_length",
            Estimator::RatioTracking => "ratio_tracking",
            Estimator::BiasedRayMarching { .. } => "biased_ray_marching",
            Estimator::UnbiasedRayMarching { .. } => "unbiased_ray_marching",
            Estimator::Naive { .. } => "naive",
            Estimator::Jackknife { .. } => "jackknife",
            Estimator::JackknifeTied { .. } => "jackknife_tied",
        }
    }

    pub fn estimate(&self, medium: &Medium, seg: &Segment, rng: &mut Pcg) -> Estimate {
        match *self {
            Estimator::TrackLength => track_length(medium, seg, rng),
            Estimator::RatioTracking => ratio_tracking(medium, seg, rng),
            Estimator::BiasedRayMarching { multiplier } => {
                biased_ray_marching(medium, seg, multiplier, rng)
            }
            Estimator::UnbiasedRayMarching { multiplier } => {
                unbiased_ray_marching(medium, seg, multiplier, rng)
            }
            Estimator::Naive { samples } => naive(medium, seg, samples, rng),
            Estimator::Jackknife { samples } => jackknife_transmittance(medium, seg, samples, rng),
            Estimator::JackknifeTied { step } => {
                let settings = JackknifeSettings {
                    estimates: 2,
                    samples: SampleCount::PerImportance { step },
                };
                jackknife_transmittance_with(medium, seg, &settings, rng)
            }
        }
    }
}

impl Estimator {
    /// (id, samples, multiplier) of the WGSL `estimate_transmittance` (media_estimators.wgsl).
    pub fn gpu_settings(&self) -> (u32, u32, f32) {
        match *self {
            Estimator::TrackLength => (0, 0, 0.0),
            Estimator::RatioTracking => (1, 0, 0.0),
            Estimator::BiasedRayMarching { multiplier } => (2, 0, multiplier),
            Estimator::UnbiasedRayMarching { multiplier } => (3, 0, multiplier),
            Estimator::Naive { samples } => (4, samples, 0.0),
            Estimator::Jackknife { samples } => (5, samples, 0.0),
            Estimator::JackknifeTied { step } => (6, 0, step),
        }
    }
}
