// The termination decision at one path vertex: WGSL twin of src/decision.rs
// (checked against it in tests/termination_gpu.rs). Self-contained: no imports, no
// bindings.

const TC_VARIANCE_BOUNDING: u32 = 0u;
const TC_MSE_MINIMISATION: u32 = 1u;
const TC_AREA_SPREAD: u32 = 2u;
const TC_FIRST_VERTEX: u32 = 3u;
const TC_PATH_TRACING: u32 = 4u;
const TC_FOUR_PI: f32 = 12.566370614359172;

struct TcRule {
    kind: u32,
    relative: u32,
    param: f32,        // t, s or c
    margin: f32,
    bias_clamp: f32,
    survival: f32,     // Russian roulette survival of a continued segment
}

struct TcPathState {
    throughput2: f32,   // (g_l^pre)^2
    path_variance: f32, // sum of P_j so far
    threshold: f32,     // absolute variance threshold of the path
    spread_sqrt: f32,   // area spread: sum of sqrt(d^2 / (p cos)) behind the primary vertex
    spread0: f32,       // area spread: primary footprint d0^2 / (4 pi cos)
    vertex: u32,        // 1 = primary hit
}

struct TcLocalStats {
    radiance: f32,       // luminance of the cache value
    variance: f32,       // E[Y^2] - E[E[Y|y]^2]
    continuation2: f32,  // E[B^2]: the rouletted part of Y = A (NEE) + B (the BSDF sample's hit)
    bias2: f32,          // E[E[Y|y]^2] - E[Y]^2
    deferred_bias2: f32, // E[(f cos / p)^2 B_next^2]
}

// A threshold no path variance reaches: path tracing.
const TC_NO_THRESHOLD: f32 = 3.0e38;

// The path's absolute threshold from the first hit's record; a relative threshold without a
// filled record there (`filled` false) has no brightness to scale: the path is path traced.
fn tc_threshold(rule: TcRule, first_radiance: f32, filled: bool) -> f32 {
    if rule.kind != TC_VARIANCE_BOUNDING {
        return 0.0;
    }
    if rule.relative == 0u {
        return rule.param;
    }
    return select(TC_NO_THRESHOLD, rule.param * first_radiance * first_radiance, filled);
}

fn tc_arrive_area_spread(state: ptr<function, TcPathState>, dist2: f32, pdf: f32, cos_in: f32) {
    let c = max(abs(cos_in), 1.0e-6);
    if (*state).vertex <= 1u {
        (*state).spread0 = dist2 / (TC_FOUR_PI * c);
    } else if pdf > 0.0 {
        (*state).spread_sqrt += sqrt(dist2 / (pdf * c));
    }
}

// The continuation weight: 1 continue, 0 terminate, alpha in (0, 1) blend (eq. 5). Updates the
// path variance as decision.rs does.
fn tc_decide(rule: TcRule, state: ptr<function, TcPathState>, s: TcLocalStats) -> f32 {
    // Roulette keeps only the continuation B (NEE is added before the survival draw):
    // E[Y'^2] = E[A^2] + 2E[AB] + E[B^2] / q, E[Y'|y] = E[Y|y]: the variance grows by (1/q - 1) E[B^2].
    let local_variance = max(s.variance + s.continuation2 * (1.0 / rule.survival - 1.0), 0.0);
    let prefixed = (*state).throughput2 * local_variance;
    switch rule.kind {
        case TC_PATH_TRACING: {
            return 1.0;
        }
        case TC_FIRST_VERTEX: {
            return 0.0;
        }
        case TC_VARIANCE_BOUNDING: {
            let t = (*state).threshold;
            if (*state).path_variance + prefixed <= t {
                (*state).path_variance += prefixed;
                return 1.0;
            }
            let alpha = sqrt(max(t - (*state).path_variance, 0.0) / prefixed);
            (*state).path_variance = t;
            return alpha;
        }
        case TC_MSE_MINIMISATION: {
            let n = rule.param;
            let current = (*state).path_variance / n + (*state).throughput2 * s.bias2;
            // The next vertex is reached with probability q and weight 1/q: E[w^2 B^2] / q.
            let deferred_bias2 = min(s.deferred_bias2 / rule.survival, rule.bias_clamp * s.bias2 / rule.margin);
            let deferred = ((*state).path_variance + prefixed) / n + (*state).throughput2 * deferred_bias2;
            if current <= rule.margin * deferred {
                return 0.0;
            }
            (*state).path_variance += prefixed;
            return 1.0;
        }
        default: {
            // TC_AREA_SPREAD
            let spread = (*state).spread_sqrt * (*state).spread_sqrt;
            return select(1.0, 0.0, (*state).vertex >= 2u && spread > rule.param * (*state).spread0);
        }
    }
}
