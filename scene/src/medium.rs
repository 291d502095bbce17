//! Participating media as a scenario declares them (`media: [...]`): a box, a procedural
//! density baked to a voxel grid, albedo and optional emission. Plain data; the `media` crate
//! bakes and renders them.

use glam::Vec3;
use serde::{Deserialize, Serialize};

/// The procedural field a medium is baked from.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub enum DensityKind {
    /// μ = `sigma_t` everywhere in the box.
    Homogeneous,
    /// A round cloud: fBm (Perlin, `octaves`, base frequency `frequency` per box) eroding a
    /// sphere, scaled to peak `sigma_t`.
    Cloud { octaves: usize, frequency: f64, seed: u32 },
    /// The paper's failure case: a thin shell of sparse, high-frequency blobs (most voxels
    /// empty, the rest at `sigma_t`), so that few samples along a ray see any density.
    Explosion { frequency: f64, seed: u32 },
}

/// One medium of a scenario.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct MediumDesc {
    pub name: String,
    pub kind: DensityKind,
    pub box_min: Vec3,
    pub box_max: Vec3,
    /// Peak extinction per world unit.
    pub sigma_t: f32,
    /// Voxels along each axis of the box.
    #[serde(default = "default_resolution")]
    pub resolution: (u32, u32, u32),
    /// Single-scattering albedo (σ_s / σ_t), per channel.
    #[serde(default = "default_albedo")]
    pub albedo: Vec3,
    /// Emitted radiance per unit extinction, if any.
    #[serde(default)]
    pub emission: Option<Vec3>,
}

fn default_resolution() -> (u32, u32, u32) {
    (64, 64, 64)
}

fn default_albedo() -> Vec3 {
    Vec3::splat(0.8)
}

/// The largest resolution along an axis a scenario may ask for (the grid is baked on load).
pub const MAX_MEDIUM_RESOLUTION: u32 = 512;

impl MediumDesc {
    /// What is wrong with the declaration, if anything (the caller adds the file and line).
    pub fn problem(&self) -> Option<String> {
        let (x, y, z) = self.resolution;
        if !(self.box_min.cmplt(self.box_max).all()) {
            return Some(format!("medium '{}': box_min {} must be below box_max {} on every axis", self.name, self.box_min, self.box_max));
        }
        if !(self.sigma_t.is_finite() && self.sigma_t >= 0.0) {
            return Some(format!("medium '{}': sigma_t {} must be a finite extinction >= 0", self.name, self.sigma_t));
        }
        if [x, y, z].iter().any(|&r| r == 0 || r > MAX_MEDIUM_RESOLUTION) {
            return Some(format!("medium '{}': resolution ({x}, {y}, {z}) must be 1 to {MAX_MEDIUM_RESOLUTION} voxels per axis", self.name));
        }
        if !(self.albedo.cmpge(Vec3::ZERO).all() && self.albedo.cmple(Vec3::ONE).all()) {
            return Some(format!("medium '{}': albedo {} must lie in [0, 1]", self.name, self.albedo));
        }
        if let Some(e) = self.emission {
            if !(e.is_finite() && e.cmpge(Vec3::ZERO).all()) {
                return Some(format!("medium '{}': emission {e} must be finite and >= 0", self.name));
            }
        }
        None
    }
}
