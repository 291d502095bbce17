//! The `Termination(...)` method's scenario settings and the cache's memory.

use super::rule::TerminationRule;
use render::error::RenderError;

/// Every field but `rule` defaults to the paper's value where it gives one (§5), else to the
/// value stated in docs/methods/termination.md.
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct TerminationSettings {
    pub rule: TerminationRule,
    /// Russian roulette survival probability of every continued segment (Fig. 7: 1, 0.6, 0.2).
    pub survival: f64,
    /// Slots of the hashed grid (records).
    pub capacity: u32,
    /// Slots probed from the home slot before an insertion fails.
    pub probe_limit: u32,
    /// Voxel size in pixel footprints at the point's camera distance (rounded up to 2^k).
    pub lod_scale: f32,
    /// Jittered lookups: stochastic interpolation between neighbouring records (§5).
    pub jitter: bool,
    /// Samples per stored vertex and propagation (the U-statistic's K; the paper: a subgroup,
    /// 32, the default). K costs no memory (one invocation loops over its samples and keeps
    /// three sums); propagation time grows about linearly with it.
    pub samples_per_vertex: u32,
    /// Vertex estimates a record averages before its mean turns exponential.
    pub max_vertices: u32,
    /// Probability that the tracer offers a primary vertex to its record (§5: 1%).
    pub store_probability: f64,
    /// Frames of propagation (and primary storing) before the first frame: the paper fills the
    /// cache to equilibrium before timing (§6).
    pub warmup_frames: u32,
    /// The radiance an absolute threshold t is stated in: the path variance is bounded by
    /// t · radiance_unit². Variance scales with the square of radiance, and the paper's t
    /// belongs to its scenes' radiance scale, not to the lab's (docs/lab/termination-radiance-scale.md).
    /// Read only with `radiance_scale: Stated`.
    pub radiance_unit: f64,
    /// Where the radiance unit comes from: the scene's own cache (`CacheMean`, the default) or
    /// `radiance_unit` as stated (the scenarios' values fitted to the paper's Table 1).
    pub radiance_scale: RadianceScale,
    /// A propagation sample whose hit has no filled record yet: its vertex estimate is left
    /// out of filled records (the default), or the sample goes on by path tracing.
    pub incomplete: Incomplete,
}

/// The radiance an absolute variance threshold t is stated in (t · unit²).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
pub enum RadianceScale {
    /// Derived from the scene: the mean luminance E[Y] over the cache's filled records when the
    /// first image reads them (after the warm-up and the first frame's fold), then fixed for
    /// the run. No result of the run's images enters it.
    #[default]
    CacheMean,
    /// `radiance_unit` as the scenario states it.
    Stated,
}

/// What propagation does with a sample whose BSDF hit has no filled record to end in.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
pub enum Incomplete {
    /// The vertex estimate (which read 0 there) may start an empty record but never updates a
    /// filled one: the kept estimates are those whose samples all reached filled records.
    #[default]
    LeaveOut,
    /// The sample continues from that hit by path tracing to the frame's max depth (one more
    /// ray to the hit, then the path tracer's loop): every estimate is complete and unbiased
    /// given the records it read.
    PathTrace,
    /// The estimate counts like any other, the empty record read as 0: the paper's propagation
    /// evaluates the cache at the hit, whatever it holds (§5), and fills the cache to
    /// equilibrium first (§6), where no hit lacks its record.
    Include,
}

impl Default for TerminationSettings {
    fn default() -> Self {
        Self {
            rule: TerminationRule::VarianceBounding { t: 0.1, relative: false },
            survival: 1.0,
            capacity: 1 << 16,
            probe_limit: 8,
            lod_scale: 8.0,
            jitter: true,
            samples_per_vertex: 32,
            max_vertices: 64,
            store_probability: 0.01,
            warmup_frames: 16,
            radiance_unit: 1.0,
            radiance_scale: RadianceScale::CacheMean,
            incomplete: Incomplete::LeaveOut,
        }
    }
}

/// Stored vertices per record (§5).
pub const VERTICES_PER_RECORD: u64 = 4;

/// The cache's buffers per record: slot words (16), record moments (48), 4 per-vertex estimates
/// (4 × 48), 4 stored vertices (4 × 32), 4 propagation candidates (4 × 32) and their 4
/// insertion requests (4 × 16).
pub const BYTES_PER_RECORD: u64 = 16 + 48 + VERTICES_PER_RECORD * (48 + 32 + 32 + 16);

impl TerminationSettings {
    pub fn validate(&self) -> Result<(), RenderError> {
        let bad = |m: String| Err(RenderError::Settings(m));
        self.rule.validate().map_err(RenderError::Settings)?;
        if !(self.survival > 0.0 && self.survival <= 1.0) {
            return bad(format!("Termination survival must be in (0, 1], got {}", self.survival));
        }
        if !(self.radiance_unit > 0.0 && self.radiance_unit.is_finite()) {
            return bad(format!(
                "Termination radiance_unit must be positive and finite, got {}",
                self.radiance_unit
            ));
        }
        if self.capacity == 0 || self.capacity > (1 << 20) {
            // 4 propagation invocations per record in one dispatch dimension (65535 × 64).
            return bad(format!(
                "Termination capacity must be in 1..=2^20 records, got {}",
                self.capacity
            ));
        }
        if self.probe_limit == 0 || self.probe_limit > self.capacity {
            return bad(format!(
                "Termination probe_limit must be in 1..=capacity, got {}",
                self.probe_limit
            ));
        }
        if self.samples_per_vertex < 2 || self.samples_per_vertex > 32 {
            return bad(format!(
                "Termination samples_per_vertex must be in 2..=32 (pairs for the marginal moment), got {}",
                self.samples_per_vertex
            ));
        }
        if self.max_vertices == 0
            || !(self.lod_scale > 0.0)
            || !(0.0..=1.0).contains(&self.store_probability)
        {
            return bad("Termination max_vertices must be >= 1, lod_scale > 0 and store_probability in [0, 1]".into());
        }
        Ok(())
    }

    /// Settings with equal keys build bit-identical records, so their rules can share one cache
    /// (one propagation a frame): everything but the rule, the survival probability and the
    /// radiance unit and scale, which only the trace reads (the cache derives its mean once for
    /// all of its tracers). Path tracing is its own key: it skips the
    /// lookup's random numbers at the first vertex, so its stored vertices differ.
    pub fn cache_key(&self) -> TerminationSettings {
        let rule = match self.rule {
            TerminationRule::PathTracing => TerminationRule::PathTracing,
            _ => TerminationRule::FirstVertex,
        };
        TerminationSettings {
            rule,
            survival: 1.0,
            radiance_unit: 1.0,
            radiance_scale: RadianceScale::CacheMean,
            ..*self
        }
    }

    /// Bytes of the cache's records (what `Gpu::check_buffer_size` sees per buffer is less).
    pub fn cache_bytes(&self) -> u64 {
        self.capacity as u64 * BYTES_PER_RECORD
    }
}
