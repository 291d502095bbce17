//! Settings of the cache, composed tiny-cuda-nn style: encoding, network, optimizer, loss, EMA
//! and reliability grid are separate parts, each with the public NRC/NIRC defaults
//! (../shared/notes/reading-the-seeds.md) and each overridable from a scenario (serde).

use serde::{Deserialize, Serialize};

use crate::optimizer_config::{AdamSettings, EmaSettings};

/// Everything that defines a cache. Two caches with equal configs, bounds and seed start from
/// identical states.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct NircCacheSettings {
    pub encoding: HashGridSettings,
    pub direction: DirectionEncoding,
    pub network: NetworkSettings,
    pub optimizer: AdamSettings,
    pub loss: LossSettings,
    pub ema: EmaSettings,
    pub reliability: ReliabilitySettings,
    /// Largest number of training records one `train` call accepts (sizes the scratch buffers).
    pub max_batch: u32,
    /// Seed of the initial weights.
    pub seed: u64,
}

impl Default for NircCacheSettings {
    fn default() -> Self {
        Self {
            encoding: HashGridSettings::default(),
            direction: DirectionEncoding::default(),
            network: NetworkSettings::default(),
            optimizer: AdamSettings::default(),
            loss: LossSettings::default(),
            ema: EmaSettings::default(),
            reliability: ReliabilitySettings::default(),
            // NRC trains on 4 batches of 16384 records per frame.
            max_batch: 16384,
            seed: 0x5eed_0fc0_ffee,
        }
    }
}

/// Multi-resolution hash grid over the scene bounds (Müller et al. 2022). Level l has resolution
/// floor(base_resolution * growth_factor^l); a level whose (resolution+1)^3 vertices fit in the
/// table is indexed densely, otherwise spatially hashed (collisions are left to the network).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct HashGridSettings {
    /// L
    pub levels: u32,
    /// F
    pub features_per_level: u32,
    /// T = 2^log2_table_size entries per level at most.
    pub log2_table_size: u32,
    pub base_resolution: u32,
    /// b, per-level growth of the resolution.
    pub growth_factor: f32,
    /// Initial entries are uniform in [-init_scale, init_scale].
    pub init_scale: f32,
}

impl Default for HashGridSettings {
    fn default() -> Self {
        // NRC/NIRC public settings: L = 16, F = 2, T in 2^15..2^19, b in 1.5..2.0.
        Self {
            levels: 16,
            features_per_level: 2,
            log2_table_size: 16,
            base_resolution: 16,
            growth_factor: 1.5,
            init_scale: 1e-4,
        }
    }
}

/// How the query direction (unit vector) enters the network, concatenated after the hash-grid
/// features of the position. The seed does not spell the encoding out; we default to real
/// spherical harmonics (tiny-cuda-nn's "SphericalHarmonics" encoding), which is smooth and cheap.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
pub enum DirectionEncoding {
    /// Position only (a plain radiance cache with no directional input).
    None,
    /// The raw components (x, y, z).
    Identity,
    /// Real spherical harmonics of `bands` bands (1..=3), bands^2 values. Default: 3 bands.
    SphericalHarmonics { bands: u32 },
}

impl Default for DirectionEncoding {
    fn default() -> Self {
        DirectionEncoding::SphericalHarmonics { bands: 3 }
    }
}

impl DirectionEncoding {
    /// Number of network inputs the direction contributes.
    pub fn dims(&self) -> u32 {
        match *self {
            DirectionEncoding::None => 0,
            DirectionEncoding::Identity => 3,
            DirectionEncoding::SphericalHarmonics { bands } => bands * bands,
        }
    }
    /// 0 = none, 1 = identity, 2 = spherical harmonics; and the band count.
    pub(crate) fn code(&self) -> (u32, u32) {
        match *self {
            DirectionEncoding::None => (0, 0),
            DirectionEncoding::Identity => (1, 0),
            DirectionEncoding::SphericalHarmonics { bands } => (2, bands),
        }
    }
}

/// Fully connected network without biases (as tiny-cuda-nn's fully fused MLP): inputs ->
/// `hidden_layers` x `width` ReLU -> 3 outputs (RGB incident radiance). Output activation: none
/// (linear), so the relative L2 loss sees the raw prediction; the cache clamps the final,
/// blended radiance to >= 0 when it answers a query.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct NetworkSettings {
    /// 16, 32 or 64.
    pub width: u32,
    /// 1..=5.
    pub hidden_layers: u32,
}

impl Default for NetworkSettings {
    fn default() -> Self {
        // 64 neurons as NRC; 2 hidden layers (NRC uses 2..5) so that one predictor's weights
        // (27.6 KiB with the default encoding) fit in 32 KiB of workgroup memory.
        Self { width: 64, hidden_layers: 2 }
    }
}

/// Relative L2 (NRC): (f - y)^2 / (sg(f)^2 + epsilon), sg = stop-gradient, averaged over the
/// batch and the three channels.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct LossSettings {
    pub epsilon: f32,
    /// Normalise each channel by its own prediction, or every channel by the luminance of the
    /// prediction (NRC's variant).
    pub normalization: LossNormalization,
}

#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize, Default)]
pub enum LossNormalization {
    #[default]
    PerChannel,
    Luminance,
}

impl Default for LossSettings {
    fn default() -> Self {
        Self { epsilon: 0.01, normalization: LossNormalization::PerChannel }
    }
}

/// Reliability grid (section 3.1/3.2 of reliability-weighted-nirc.txt).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct ReliabilitySettings {
    /// Voxels per axis over the scene bounds before hashing.
    pub resolution: u32,
    /// 2^log2_cells hashed cells; collisions are ignored as in the paper.
    pub log2_cells: u32,
    /// λ of the moment EMAs.
    pub lambda: f32,
    /// K: grid updates (committed training steps, see `ReliabilityGrid`) before the
    /// reliabilities are used; until then queries use EMA-only.
    pub warmup: u32,
    /// κ, gain of the logistic blend weight.
    pub kappa: f32,
    /// ε added to both variances in r = c / sqrt((s^y + ε)(s^f + ε)).
    pub epsilon: f32,
    /// How a training step's samples move the moments.
    pub update: MomentUpdate,
}

/// How the reliability moments follow the training samples.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize, Default, Hash)]
pub enum MomentUpdate {
    /// The paper's rule: X <- λ X + (1 - λ) x once per sample, in record order, in the sample's
    /// cell (a memory of about 1 / (1 - λ) = 10 samples).
    #[default]
    PerSample,
    /// One step per training step towards the mean of the step's samples in the cell (a memory
    /// of about 10 steps): the lab's earlier rule, kept for comparison.
    BatchMean,
}

impl Default for ReliabilitySettings {
    fn default() -> Self {
        // λ ≈ 0.9, K = 128, κ = 4 from the paper; resolution, table size and ε are ours.
        Self {
            resolution: 32,
            log2_cells: 16,
            lambda: 0.9,
            warmup: 128,
            kappa: 4.0,
            epsilon: 1e-4,
            update: MomentUpdate::PerSample,
        }
    }
}

/// Which predictor(s) answer a query.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize, Default)]
pub enum PredictorMode {
    /// The EMA weights only (NRC's inference).
    EmaOnly,
    /// The trained (High-LR) weights only.
    HighLrOnly,
    /// L = (1 - σ) f_EMA + σ f_cur per query.
    #[default]
    Blend,
    /// The predictor of higher reliability r̄ (ties go to EMA).
    Switch,
    /// L = (1 - σ) f_EMA + σ f_cur per query with σ from another reliability statistic of the
    /// same cell (`BlendBy(Correlation)` is `Blend`).
    BlendBy(ReliabilityStatistic),
    /// L = (1 - σ) f_EMA + σ f_cur with a constant σ in [0, 1] (a control for the blend: the
    /// same two predictors without the reliability grid, warm-up included).
    Fixed(f32),
}

/// What a blend's σ is computed from, per reliability cell (all from the moments the grid keeps).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, Serialize, Deserialize, Default)]
pub enum ReliabilityStatistic {
    /// The paper's eq. 3: r̄ = mean over RGB of the correlation of y and f;
    /// σ = logistic(κ (r̄_cur - r̄_EMA)). Blind to a predictor off by a factor or an offset.
    #[default]
    Correlation,
    /// The relative mean squared error e = mean over RGB of E_λ[(y - f)²] / (E_λ[y²] + ε), with
    /// E_λ[(y - f)²] = Q^y - 2 C^{y,f} + Q^f (the EMA is linear); σ = (e_EMA + ε) /
    /// (e_cur + e_EMA + 2ε), inverse-error weighting. Sees a predictor's bias (lag) as well
    /// as its noise.
    RelativeError,
    /// The scale mismatch d = |ln ρ| of ρ = (max(Σ_c C^{y,f}_c, 0) + ε) / (Σ_c Q^f_c + ε), the
    /// least-squares gain from f to y through the origin (uncentred second moments);
    /// σ = logistic(κ (d_EMA - d_cur)). Target noise independent of f leaves C^{y,f} unbiased,
    /// so ρ sees a predictor off by a factor without the targets' noise floor.
    ScaleRatio,
}

// σ of `Fixed` is compared and hashed by its bits (methods with equal settings share a cache).
impl Eq for PredictorMode {}

impl std::hash::Hash for PredictorMode {
    fn hash<H: std::hash::Hasher>(&self, state: &mut H) {
        self.code().hash(state);
        if let PredictorMode::Fixed(sigma) = self {
            sigma.to_bits().hash(state);
        }
        if let PredictorMode::BlendBy(statistic) = self {
            statistic.hash(state);
        }
    }
}

impl PredictorMode {
    /// Whether the mode blends or chooses by reliability, and so writes a preference map (its σ
    /// per pixel, the paper's Fig. 3).
    pub fn has_preference_map(self) -> bool {
        matches!(self, PredictorMode::Blend | PredictorMode::Switch | PredictorMode::BlendBy(_))
    }

    pub(crate) fn code(self) -> u32 {
        match self {
            PredictorMode::EmaOnly => 0,
            PredictorMode::HighLrOnly => 1,
            PredictorMode::Blend => 2,
            PredictorMode::Switch => 3,
            PredictorMode::BlendBy(ReliabilityStatistic::Correlation) => 2,
            PredictorMode::Fixed(_) => 5,
            PredictorMode::BlendBy(ReliabilityStatistic::RelativeError) => 6,
            PredictorMode::BlendBy(ReliabilityStatistic::ScaleRatio) => 7,
        }
    }

    /// σ of `Fixed`, 0 for the others (unused by them).
    pub(crate) fn fixed_sigma(self) -> f32 {
        match self {
            PredictorMode::Fixed(sigma) => sigma,
            _ => 0.0,
        }
    }
}

impl NircCacheSettings {
    /// Refuses settings outside what the cache implements, naming the field.
    pub fn validate(&self) -> Result<(), crate::NircError> {
        let bad = |what: &str, why: String| Err(crate::NircError::Config(format!("{what}: {why}")));
        let e = &self.encoding;
        if e.levels == 0 || e.levels > 32 {
            return bad("encoding.levels", format!("{} not in 1..=32", e.levels));
        }
        if e.features_per_level == 0 || e.features_per_level > 8 {
            return bad(
                "encoding.features_per_level",
                format!("{} not in 1..=8", e.features_per_level),
            );
        }
        if !(4..=24).contains(&e.log2_table_size) {
            return bad("encoding.log2_table_size", format!("{} not in 4..=24", e.log2_table_size));
        }
        if e.base_resolution == 0 || !(e.growth_factor >= 1.0) {
            return bad(
                "encoding",
                format!(
                    "base_resolution {} must be >= 1 and growth_factor {} >= 1",
                    e.base_resolution, e.growth_factor
                ),
            );
        }
        if let DirectionEncoding::SphericalHarmonics { bands } = self.direction
            && !(1..=3).contains(&bands)
        {
            return bad("direction.SphericalHarmonics.bands", format!("{bands} not in 1..=3"));
        }
        let n = &self.network;
        if !(1..=128).contains(&n.width) {
            return bad(
                "network.width",
                format!("{} not in 1..=128 (16, 32 or 64 expected)", n.width),
            );
        }
        if !(1..=5).contains(&n.hidden_layers) {
            return bad("network.hidden_layers", format!("{} not in 1..=5", n.hidden_layers));
        }
        let o = &self.optimizer;
        if !(o.learning_rate > 0.0)
            || !(0.0..1.0).contains(&o.beta1)
            || !(0.0..1.0).contains(&o.beta2)
            || !(o.epsilon >= 0.0)
        {
            return bad("optimizer", format!("{o:?}: need lr > 0, 0 <= β < 1, ε >= 0"));
        }
        if !(self.loss.epsilon > 0.0) {
            return bad("loss.epsilon", format!("{} must be > 0", self.loss.epsilon));
        }
        if !(0.0..1.0).contains(&self.ema.alpha) {
            return bad("ema.alpha", format!("{} not in [0, 1)", self.ema.alpha));
        }
        if self.optimizer.sparse_grid {
            crate::cpu::optimizer::BiasPowers::new(&self.optimizer, &self.ema)?;
        }
        let r = &self.reliability;
        if r.resolution == 0 || !(1..=24).contains(&r.log2_cells) {
            return bad(
                "reliability",
                format!(
                    "resolution {} must be >= 1 and log2_cells {} in 1..=24",
                    r.resolution, r.log2_cells
                ),
            );
        }
        if !(0.0..1.0).contains(&r.lambda) || !(r.kappa > 0.0) || !(r.epsilon >= 0.0) {
            return bad("reliability", format!("{r:?}: need 0 <= λ < 1, κ > 0, ε >= 0"));
        }
        if self.max_batch == 0 {
            return bad("max_batch", "must be >= 1".into());
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn defaults_are_the_public_nrc_settings_and_valid() {
        let c = NircCacheSettings::default();
        c.validate().unwrap();
        assert_eq!((c.encoding.levels, c.encoding.features_per_level), (16, 2));
        assert_eq!((c.optimizer.beta2, c.optimizer.epsilon, c.ema.alpha), (0.99, 1e-15, 0.99));
        assert_eq!(
            (c.reliability.lambda, c.reliability.warmup, c.reliability.kappa),
            (0.9, 128, 4.0)
        );
        assert_eq!(c.loss.epsilon, 0.01);
    }

    #[test]
    fn partial_settings_fill_in_defaults_and_unknown_fields_are_refused() {
        let c: NircCacheSettings = serde_json::from_str(
            r#"{"network": {"width": 32}, "direction": {"SphericalHarmonics": {"bands": 2}}}"#,
        )
        .unwrap();
        assert_eq!(c.network, NetworkSettings { width: 32, hidden_layers: 2 });
        assert_eq!(c.direction.dims(), 4);
        assert_eq!(c.encoding, HashGridSettings::default());
        let back: NircCacheSettings =
            serde_json::from_str(&serde_json::to_string(&c).unwrap()).unwrap();
        assert_eq!(back, c);
        let err = serde_json::from_str::<NircCacheSettings>(r#"{"network": {"widht": 32}}"#)
            .unwrap_err()
            .to_string();
        assert!(err.contains("widht"), "{err}");
        let bad = NircCacheSettings {
            network: NetworkSettings { width: 64, hidden_layers: 7 },
            ..Default::default()
        };
        let err = bad.validate().unwrap_err().to_string();
        assert!(err.contains("network.hidden_layers") && err.contains('7'), "{err}");
    }
}
