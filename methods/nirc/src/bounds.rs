//! The scene's axis-aligned bounding box, which both grids (hash-grid encoding and reliability
//! grid) are laid over.

use serde::{Deserialize, Serialize};

#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct SceneBounds {
    pub min: [f32; 3],
    pub max: [f32; 3],
}

impl SceneBounds {
    pub fn new(min: [f32; 3], max: [f32; 3]) -> Self {
        Self { min, max }
    }

    /// 1 / extent per axis; a flat axis counts as extent 1 so that it maps to 0.
    pub fn inv_extent(&self) -> [f32; 3] {
        std::array::from_fn(|i| {
            let e = self.max[i] - self.min[i];
            if e > 0.0 { 1.0 / e } else { 1.0 }
        })
    }

    /// Linear map of the box to [0,1]^3, clamped (the GPU computes the same expression).
    pub fn normalize(&self, p: [f32; 3]) -> [f32; 3] {
        let inv = self.inv_extent();
        std::array::from_fn(|i| ((p[i] - self.min[i]) * inv[i]).clamp(0.0, 1.0))
    }
}
