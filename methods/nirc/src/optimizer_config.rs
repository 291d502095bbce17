//! The optimiser's settings, a part of [`crate::config::NircCacheSettings`] of their own because the
//! optimiser (`cpu::optimizer`, the GPU's training pass) reads them and the config's check builds
//! the optimiser's tables: Adam and the EMA of the weights, with NRC's defaults.

use serde::{Deserialize, Serialize};

/// Adam (Kingma and Ba 2014), applied to every parameter (MLP weights and hash-table entries).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct AdamSettings {
    pub learning_rate: f32,
    pub beta1: f32,
    pub beta2: f32,
    pub epsilon: f32,
    /// Sparse updates of the hash grid (tiny-cuda-nn's Adam, which NRC uses): a table entry
    /// whose gradient is exactly zero this step is left alone by Adam and by the EMA, and each
    /// entry debiases with its own step count. The MLP weights stay dense. Off by default (plain
    /// Adam on every parameter); left out of the serialised settings when off, so that warm-start
    /// keys of dense caches do not change.
    #[serde(skip_serializing_if = "std::ops::Not::not")]
    pub sparse_grid: bool,
}

impl Default for AdamSettings {
    fn default() -> Self {
        // NRC: lr 1e-3..1e-2, β2 = 0.99, ε = 1e-15; β1 = 0.9 (Adam's default).
        Self { learning_rate: 1e-2, beta1: 0.9, beta2: 0.99, epsilon: 1e-15, sparse_grid: false }
    }
}

/// EMA of the weights, debiased: w̄_t = (α w̄_{t-1} (1 - α^{t-1}) + (1 - α) w_t) / (1 - α^t).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct EmaSettings {
    pub alpha: f32,
}

impl Default for EmaSettings {
    fn default() -> Self {
        Self { alpha: 0.99 }
    }
}
