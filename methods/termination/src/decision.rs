//! The termination decision at one path vertex (the paper's Fig. 3, reconstructed from §4.2,
//! §4.3 and §5; the WGSL twin is shaders/decision.wgsl, checked against this one in
//! tests/termination_gpu.rs).
//!
//! A path arrives at vertex x_l (l = 1 is the primary hit) with its squared prefix weight
//! (g_l^pre)² (`throughput2`: the squared luminance of the throughput) and its path variance
//! Σ_{j<l} P_j. The cache record at x_l gives the local statistics; the decision is to
//! terminate into the cache there, to continue, or (variance bounding) to blend the cache with
//! one more segment that then terminates at x_{l+1} (eq. 5).

use super::rule::TerminationRule;

/// The cache's statistics at a vertex (luminance), as the record at the vertex holds them.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct LocalStats {
    /// The cache value rc(x_l) (its luminance): the relative threshold's brightness.
    pub radiance: f64,
    /// Average local variance E[V[Y|y]] = E[Y²] − E[E[Y|y]²] of one segment, without roulette.
    pub variance: f64,
    /// E[B²], the second moment of the segment's rouletted part: Y = A + B, A the direct light
    /// (NEE, added before the survival draw), B the BSDF sample's hit (its emission and the
    /// cache there), which roulette keeps with probability q and scales by 1/q.
    pub continuation2: f64,
    /// Average squared local bias E[E[Y|y]²] − E[Y]² (B_l² of eq. 3).
    pub bias2: f64,
    /// Expected squared bias at the next vertex, prefixed by the segment's weight:
    /// E[(f cos/p)² B_{l+1}²] (the deferred bias, pd_bias).
    pub deferred_bias2: f64,
}

impl LocalStats {
    /// Local variance of continuing under Russian roulette of survival `q`. Only the
    /// continuation is rouletted: Y' = A + χB/q, so E[Y'²] = E[A²] + 2E[AB] + E[B²]/q = E[Y²] +
    /// (1/q − 1)E[B²] while E[Y'|y] = E[Y|y]: the variance grows by (1/q − 1)E[B²].
    pub fn variance_with_roulette(&self, q: f64) -> f64 {
        (self.variance + self.continuation2 * (1.0 / q - 1.0)).max(0.0)
    }

    /// The deferred bias under roulette of survival `q`: the next vertex is reached with
    /// probability q and weight 1/q, so E[χ (w/q)² B²] = E[w² B²] / q.
    pub fn deferred_bias2_with_roulette(&self, q: f64) -> f64 {
        self.deferred_bias2 / q
    }
}

/// What the path carries between vertices for the decision.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct PathState {
    /// (g_l^pre)²: squared luminance of the path throughput up to this vertex.
    pub throughput2: f64,
    /// Σ_{j<l} P_j: the path variance so far.
    pub path_variance: f64,
    /// The absolute variance threshold (t, or t · rc(x_1)² for the relative rule).
    pub threshold: f64,
    /// Area spread: Σ sqrt(d² / (p cos)) over the segments behind the primary vertex.
    pub spread_sqrt: f64,
    /// Area spread: the primary footprint d₀² / (4π cos θ₁).
    pub spread0: f64,
    /// Vertex index of the path (1 = primary hit).
    pub vertex: u32,
}

/// The decision at a vertex.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Decision {
    /// Trace one more segment from here (NEE + BSDF sample), decide again at its hit.
    Continue,
    /// Take the cache value here; the path ends.
    Terminate,
    /// (1 − α) · cache here + α · one more segment that terminates into the cache at its hit
    /// (eq. 5), 0 < α < 1.
    Blend { alpha: f64 },
}

impl Decision {
    /// Weight of the continuation: 1 continue, 0 terminate, α blend.
    pub fn alpha(&self) -> f64 {
        match *self {
            Decision::Continue => 1.0,
            Decision::Terminate => 0.0,
            Decision::Blend { alpha } => alpha,
        }
    }
}

/// The absolute variance threshold of a path from the cache value at its first hit, `None`
/// where the first hit has no filled record: the relative threshold then has no brightness to
/// scale, and the path is path traced (infinite threshold) as at any vertex without a record.
pub fn path_threshold(rule: &TerminationRule, first_radiance: Option<f64>) -> f64 {
    match *rule {
        TerminationRule::VarianceBounding { t, relative: true } => match first_radiance {
            Some(c) => t * c * c,
            None => f64::INFINITY,
        },
        TerminationRule::VarianceBounding { t, relative: false } => t,
        _ => 0.0,
    }
}

/// Area spread bookkeeping on arrival at a vertex over a segment of squared length `dist2`,
/// chosen with solid-angle pdf `pdf` (ignored at the primary vertex), landing at cosine `cos`.
pub fn arrive_area_spread(state: &mut PathState, dist2: f64, pdf: f64, cos: f64) {
    let cos = cos.abs().max(1.0e-6);
    if state.vertex <= 1 {
        state.spread0 = dist2 / (4.0 * std::f64::consts::PI * cos);
    } else if pdf > 0.0 {
        state.spread_sqrt += (dist2 / (pdf * cos)).sqrt();
    }
}

/// The decision at `state.vertex` with the record's `stats`; updates the path variance.
/// `survival` is the Russian roulette's survival probability of the continuation (1 = none).
pub fn decide(
    rule: &TerminationRule,
    survival: f64,
    state: &mut PathState,
    stats: &LocalStats,
) -> Decision {
    let local_variance = stats.variance_with_roulette(survival);
    let prefixed = state.throughput2 * local_variance; // P_l
    match *rule {
        TerminationRule::PathTracing => Decision::Continue,
        TerminationRule::FirstVertex => Decision::Terminate,
        TerminationRule::VarianceBounding { .. } => {
            let t = state.threshold;
            if state.path_variance + prefixed <= t {
                state.path_variance += prefixed;
                return Decision::Continue;
            }
            // Eq. 5: α² P_l fills the rest of the budget exactly.
            let alpha = ((t - state.path_variance).max(0.0) / prefixed).sqrt();
            state.path_variance = t;
            if alpha > 0.0 { Decision::Blend { alpha } } else { Decision::Terminate }
        }
        TerminationRule::MseMinimisation { s, margin, bias_clamp } => {
            // Eq. 4 for this path: current = terminate here, deferred = one more segment then
            // terminate at the next vertex. The accumulated path variance appears in both, so
            // the margin factor lets the prefix weigh in.
            let current = state.path_variance / s + state.throughput2 * stats.bias2;
            let deferred_bias2 =
                stats.deferred_bias2_with_roulette(survival).min(bias_clamp * stats.bias2 / margin);
            let deferred =
                (state.path_variance + prefixed) / s + state.throughput2 * deferred_bias2;
            if current <= margin * deferred {
                Decision::Terminate
            } else {
                state.path_variance += prefixed;
                Decision::Continue
            }
        }
        TerminationRule::AreaSpread { c } => {
            let spread = state.spread_sqrt * state.spread_sqrt;
            if state.vertex >= 2 && spread > c * state.spread0 {
                Decision::Terminate
            } else {
                Decision::Continue
            }
        }
    }
}
