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
    /// Mean over vertices of the square of the per-vertex sample mean: with `mean` it gives the
    /// spread of the vertex means, and so the variance of `mean` itself.
    pub mean_sq: f64,
    /// Σ wᵢ² of the weights the running mean gave its vertices (1/n each while n ≤
    /// max_vertices, then exponential): Var(mean) = σ² Σ wᵢ² for vertex means of variance σ².
    pub weight2: f64,
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
        let a = 1.0 / n;
        self.mean += (e[0] - self.mean) * a;
        self.second += (e[1] - self.second) * a;
        self.marginal += (e[2] - self.marginal) * a;
        self.mean_sq += (e[0] * e[0] - self.mean_sq) * a;
        self.weight2 = (1.0 - a) * (1.0 - a) * self.weight2 + a * a;
        self.vertices = n;
    }

    /// An unbiased estimate of E[Y]²: the running mean's square less its own variance,
    /// mean² − Var(mean). The weighted spread of the vertex means, mean_sq − mean², has
    /// expectation σ²(1 − Σwᵢ²), so Var(mean) = σ²Σwᵢ² is estimated by
    /// (mean_sq − mean²) Σwᵢ² / (1 − Σwᵢ²). One vertex (Σwᵢ² = 1) has no spread to measure.
    pub fn mean_squared(&self) -> f64 {
        mean_squared_unbiased(self.mean, self.mean_sq, self.weight2)
    }

    /// Average variance E[V[Y|y]] = E[Y²] − E[E[Y|y]²] (appendix A), not below zero.
    pub fn average_variance(&self) -> f64 {
        (self.second - self.marginal).max(0.0)
    }

    /// Average squared bias E[(E[Y|y] − E[Y])²] = E[E[Y|y]²] − E[Y]², not below zero.
    pub fn squared_bias(&self) -> f64 {
        self.squared_bias_estimate().max(0.0)
    }

    /// The unclamped, unbiased estimate of the average squared bias: E[E[Y|y]²] (mean of
    /// per-vertex U-statistics) less the unbiased E[Y]² ([`RecordMoments::mean_squared`]).
    pub fn squared_bias_estimate(&self) -> f64 {
        self.marginal - self.mean_squared()
    }

    /// The plain variance E[Y²] − E[Y]² that overestimates the local variance by the bias.
    pub fn total_variance(&self) -> f64 {
        (self.second - self.mean * self.mean).max(0.0)
    }
}

/// mean² − Var(mean) from a weighted running mean, the weighted mean of the squared vertex
/// means and the weights' Σwᵢ² (the WGSL twin is termination.wgsl's `tc_mean_squared`).
pub fn mean_squared_unbiased(mean: f64, mean_sq: f64, weight2: f64) -> f64 {
    if weight2 >= 1.0 {
        return mean * mean;
    }
    mean * mean - (mean_sq - mean * mean) * weight2 / (1.0 - weight2)
}
