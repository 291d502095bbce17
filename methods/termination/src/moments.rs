//! A cache record's three moments (§4.4): E[Y], E[Y²] and the marginal second moment
//! E[E[Y|y]²], where Y is the one-segment estimate at a stored vertex y (NEE + one BSDF sample
//! ending in the cache at its hit) and the expectation runs over the record's vertices.
//!
//! The marginal moment comes from K ≥ 2 independent samples at one vertex: each pair's product
//! is an unbiased estimate of E[Y|y]² (E[Y₀Y₁] = E[Y₀]E[Y₁]), and the U-statistic averages all
//! K(K-1)/2 pairs: ((ΣY)² − ΣY²) / (K(K−1)).

/// Running sums of one record, one vertex batch at a time. Every batch has the same weight
/// (one vertex), so the record's moments are plain means over vertices of per-vertex means.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct RecordMoments {
    /// Vertices folded in.
    pub vertices: f64,
    /// Mean over vertices of the per-vertex sample mean: E[Y].
    pub mean: f64,
    /// Mean over vertices of the per-vertex mean of Y²: E[Y²].
    pub second: f64,
    /// Mean over vertices of the per-vertex U-statistic over pairs: E[E[Y|y]²].
    pub marginal: f64,
}

/// One vertex's K samples reduced to the three per-vertex estimates (mean, mean of squares,
/// mean of pair products). `None` for fewer than two samples (no pair).
pub fn vertex_estimates(samples: &[f64]) -> Option<[f64; 3]> {
    let k = samples.len();
    if k < 2 {
        return None;
    }
    let sum: f64 = samples.iter().sum();
    let sum_sq: f64 = samples.iter().map(|y| y * y).sum();
    let k = k as f64;
    Some([sum / k, sum_sq / k, (sum * sum - sum_sq) / (k * (k - 1.0))])
}

impl RecordMoments {
    /// Folds one vertex's K samples in; `max_vertices` caps the running mean's count (then an
    /// exponential average of weight 1/max_vertices, which lets the record follow a change).
    pub fn add_vertex(&mut self, samples: &[f64], max_vertices: f64) {
        let Some(e) = vertex_estimates(samples) else { return };
        self.add_estimates(e, max_vertices);
    }

    /// Folds per-vertex estimates (mean, second, pair product) in.
    pub fn add_estimates(&mut self, e: [f64; 3], max_vertices: f64) {
        let n = (self.vertices + 1.0).min(max_vertices);
        self.mean += (e[0] - self.mean) / n;
        self.second += (e[1] - self.second) / n;
        self.marginal += (e[2] - self.marginal) / n;
        self.vertices = n;
    }

    /// Average variance E[V[Y|y]] = E[Y²] − E[E[Y|y]²] (appendix A), not below zero.
    pub fn average_variance(&self) -> f64 {
        (self.second - self.marginal).max(0.0)
    }

    /// Average squared bias E[(E[Y|y] − E[Y])²] = E[E[Y|y]²] − E[Y]², not below zero.
    pub fn squared_bias(&self) -> f64 {
        (self.marginal - self.mean * self.mean).max(0.0)
    }

    /// The plain variance E[Y²] − E[Y]² that overestimates the local variance by the bias.
    pub fn total_variance(&self) -> f64 {
        (self.second - self.mean * self.mean).max(0.0)
    }
}
