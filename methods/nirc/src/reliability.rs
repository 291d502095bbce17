//! Reliability grid (reliability-weighted-nirc.txt, sections 3.1 and 3.2), CPU reference.
//!
//! A single-resolution voxel grid over the scene bounds: a position is normalised to the box,
//! truncated to integer voxel coordinates and hashed into 2^log2_cells cells; collisions are
//! ignored. Each cell keeps, per colour channel, EMAs (parameter λ) of the target moments
//! M^y, Q^y (shared) and, per predictor (High-LR "cur" and EMA), M^f, Q^f, C^{y,f}.
//!
//! One *update of the grid* is one committed training step. By default (`MomentUpdate::PerSample`,
//! the paper's rule) every sample moves its cell's moments, X <- λ X + (1 - λ) x, in record
//! order; on the GPU one invocation per cell (the owner: its first sample) replays the cell's
//! samples in that order, so the result does not depend on thread order.
//! `MomentUpdate::BatchMean` instead moves each cell once towards the mean of its samples in the
//! step (exact fixed-point sums). Cells without samples are unchanged. The warm-up K counts grid
//! updates (committed steps) for the whole grid.

use crate::bounds::SceneBounds;
use crate::config::{MomentUpdate, PredictorMode, ReliabilitySettings, ReliabilityStatistic};
use crate::fixed_sum::FixedSum;
use crate::layout::spatial_hash;
use crate::records::ReliabilitySample;

/// Floats per cell: [M^y, Q^y, M^f_cur, Q^f_cur, C^{y,f}_cur, M^f_ema, Q^f_ema, C^{y,f}_ema] x RGB.
pub const MOMENTS_PER_CELL: usize = 24;
const CUR: usize = 6;
const EMA: usize = 15;

pub fn cell_count(config: &ReliabilitySettings) -> u32 {
    1 << config.log2_cells
}

/// The hashed cell of a world-space position.
pub fn cell_index(config: &ReliabilitySettings, bounds: &SceneBounds, position: [f32; 3]) -> u32 {
    let p = bounds.normalize(position);
    let r = config.resolution;
    let v: [u32; 3] = std::array::from_fn(|a| ((p[a] * r as f32) as u32).min(r - 1));
    spatial_hash(v[0], v[1], v[2]) & (cell_count(config) - 1)
}

/// The 24 quantities a sample contributes, in the order of the moments.
pub fn sample_quantities(s: &ReliabilitySample) -> [f32; MOMENTS_PER_CELL] {
    let mut q = [0.0; MOMENTS_PER_CELL];
    for c in 0..3 {
        let (y, fc, fe) = (s.target_rgb[c], s.f_cur[c], s.f_ema[c]);
        q[c] = y;
        q[3 + c] = y * y;
        q[CUR + c] = fc;
        q[CUR + 3 + c] = fc * fc;
        q[CUR + 6 + c] = y * fc;
        q[EMA + c] = fe;
        q[EMA + 3 + c] = fe * fe;
        q[EMA + 6 + c] = y * fe;
    }
    q
}

/// One grid update from a batch of samples, as the GPU computes it (see the module docs).
/// Returns false (and changes nothing) if a sample is not finite.
pub fn update(
    config: &ReliabilitySettings,
    bounds: &SceneBounds,
    moments: &mut [f32],
    samples: &[ReliabilitySample],
) -> bool {
    let cells = cell_count(config) as usize;
    assert_eq!(
        moments.len(),
        cells * MOMENTS_PER_CELL,
        "reliability moments sized for another grid"
    );
    if config.update == MomentUpdate::PerSample {
        let finite = samples.iter().all(|s| {
            (0..3).all(|c| {
                s.target_rgb[c].is_finite() && s.f_cur[c].is_finite() && s.f_ema[c].is_finite()
            })
        });
        if finite {
            for s in samples {
                let cell = cell_index(config, bounds, [s.position[0], s.position[1], s.position[2]])
                    as usize;
                for (k, q) in sample_quantities(s).into_iter().enumerate() {
                    let i = cell * MOMENTS_PER_CELL + k;
                    moments[i] = ema_step(config.lambda, moments[i], q);
                }
            }
        }
        return finite;
    }
    let mut sums = vec![FixedSum::default(); cells * MOMENTS_PER_CELL];
    let mut counts = vec![0u32; cells];
    for s in samples {
        let cell =
            cell_index(config, bounds, [s.position[0], s.position[1], s.position[2]]) as usize;
        counts[cell] += 1;
        for (k, q) in sample_quantities(s).into_iter().enumerate() {
            if !sums[cell * MOMENTS_PER_CELL + k].add_clamped(q) {
                return false;
            }
        }
    }
    for (cell, &count) in counts.iter().enumerate().take(cells) {
        if count == 0 {
            continue;
        }
        for k in 0..MOMENTS_PER_CELL {
            let i = cell * MOMENTS_PER_CELL + k;
            moments[i] = ema_step(config.lambda, moments[i], sums[i].to_f32() / count as f32);
        }
    }
    true
}

#[inline]
pub fn ema_step(lambda: f32, x: f32, mean: f32) -> f32 {
    lambda * x + (1.0 - lambda) * mean
}

/// Eq. 3 averaged over RGB: (r̄_cur, r̄_ema) of one cell.
pub fn reliabilities(config: &ReliabilitySettings, cell_moments: &[f32]) -> (f32, f32) {
    let m = cell_moments;
    let r = |p: usize| {
        let mut sum = 0.0f32;
        for c in 0..3 {
            let (my, qy) = (m[c], m[3 + c]);
            let (mf, qf, cyf) = (m[p + c], m[p + 3 + c], m[p + 6 + c]);
            let sy = (qy - my * my).max(0.0);
            let sf = (qf - mf * mf).max(0.0);
            let cov = cyf - my * mf;
            sum += cov / ((sy + config.epsilon) * (sf + config.epsilon)).sqrt();
        }
        sum / 3.0
    };
    (r(CUR), r(EMA))
}

/// (e_cur, e_ema) of one cell: per predictor the mean over RGB of the EMA of its squared error
/// against the targets, relative to the EMA of the targets' square. The EMA is linear, so
/// E_λ[(y - f)²] = Q^y - 2 C^{y,f} + Q^f from the moments the grid keeps (clamped at 0 against
/// rounding).
pub fn relative_errors(config: &ReliabilitySettings, cell_moments: &[f32]) -> (f32, f32) {
    let m = cell_moments;
    let e = |p: usize| {
        let mut sum = 0.0f32;
        for c in 0..3 {
            let qy = m[3 + c];
            let (qf, cyf) = (m[p + 3 + c], m[p + 6 + c]);
            let squared_error = (qy - 2.0 * cyf + qf).max(0.0);
            sum += squared_error / (qy + config.epsilon);
        }
        sum / 3.0
    };
    (e(CUR), e(EMA))
}

/// Inverse-error weighting of the High-LR predictor: σ = (e_EMA + ε) / (e_cur + e_EMA + 2ε)
/// (an even blend where both errors vanish, as in an empty cell).
pub fn inverse_error_weight(config: &ReliabilitySettings, e_cur: f32, e_ema: f32) -> f32 {
    (e_ema + config.epsilon) / (e_cur + e_ema + 2.0 * config.epsilon)
}

/// (d_cur, d_ema) of one cell: |ln ρ| of each predictor's gain ρ = (max(Σ_c C^{y,f}_c, 0) + ε) /
/// (Σ_c Q^f_c + ε), the least-squares factor from f to y through the origin.
pub fn scale_mismatches(config: &ReliabilitySettings, cell_moments: &[f32]) -> (f32, f32) {
    let m = cell_moments;
    let d = |p: usize| {
        let (mut cyf, mut qf) = (0.0f32, 0.0f32);
        for c in 0..3 {
            qf += m[p + 3 + c];
            cyf += m[p + 6 + c];
        }
        ((cyf.max(0.0) + config.epsilon) / (qf + config.epsilon)).ln().abs()
    };
    (d(CUR), d(EMA))
}

/// Weight of the High-LR predictor for a query in a cell with these moments.
pub fn high_lr_weight(
    config: &ReliabilitySettings,
    mode: PredictorMode,
    grid_updates: u32,
    cell_moments: &[f32],
) -> f32 {
    match mode {
        PredictorMode::EmaOnly => 0.0,
        PredictorMode::HighLrOnly => 1.0,
        PredictorMode::Fixed(sigma) => sigma,
        // During warm-up the markers are disabled: the EMA baseline answers.
        _ if grid_updates < config.warmup => 0.0,
        PredictorMode::Blend | PredictorMode::BlendBy(ReliabilityStatistic::Correlation) => {
            let (r_cur, r_ema) = reliabilities(config, cell_moments);
            1.0 / (1.0 + (-config.kappa * (r_cur - r_ema)).exp())
        }
        PredictorMode::BlendBy(ReliabilityStatistic::RelativeError) => {
            let (e_cur, e_ema) = relative_errors(config, cell_moments);
            inverse_error_weight(config, e_cur, e_ema)
        }
        PredictorMode::BlendBy(ReliabilityStatistic::ScaleRatio) => {
            let (d_cur, d_ema) = scale_mismatches(config, cell_moments);
            1.0 / (1.0 + (-config.kappa * (d_ema - d_cur)).exp())
        }
        PredictorMode::Switch => {
            let (r_cur, r_ema) = reliabilities(config, cell_moments);
            if r_cur > r_ema { 1.0 } else { 0.0 }
        }
    }
}

/// L̂ = (1 - σ) f_EMA + σ f_cur, clamped to >= 0.
pub fn combine(sigma: f32, f_cur: [f32; 3], f_ema: [f32; 3]) -> [f32; 3] {
    std::array::from_fn(|c| ((1.0 - sigma) * f_ema[c] + sigma * f_cur[c]).max(0.0))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn lcg(state: &mut u64) -> f32 {
        *state = state.wrapping_mul(6364136223846793005).wrapping_add(1442695040888963407);
        ((*state >> 40) as f32) / (1u64 << 24) as f32
    }

    fn config() -> ReliabilitySettings {
        ReliabilitySettings { resolution: 4, log2_cells: 6, warmup: 8, ..Default::default() }
    }

    /// Feeds `frames` updates of one sample each into the cell at the origin.
    fn run(
        frames: usize,
        mut sample: impl FnMut(usize) -> ([f32; 3], [f32; 3], [f32; 3]),
    ) -> Vec<f32> {
        let cfg = config();
        let bounds = SceneBounds::new([0.0; 3], [1.0; 3]);
        let mut moments = vec![0.0; cell_count(&cfg) as usize * MOMENTS_PER_CELL];
        for t in 0..frames {
            let (y, fc, fe) = sample(t);
            let s = ReliabilitySample {
                position: [0.1, 0.1, 0.1, 0.0],
                target_rgb: [y[0], y[1], y[2], 0.0],
                f_cur: [fc[0], fc[1], fc[2], 0.0],
                f_ema: [fe[0], fe[1], fe[2], 0.0],
            };
            assert!(update(&cfg, &bounds, &mut moments, &[s]));
        }
        let cell = cell_index(&cfg, &bounds, [0.1, 0.1, 0.1]) as usize;
        moments[cell * MOMENTS_PER_CELL..(cell + 1) * MOMENTS_PER_CELL].to_vec()
    }

    #[test]
    fn linearly_related_stream_has_correlation_one() {
        let mut rng = 1u64;
        let m = run(400, |_| {
            let y = [lcg(&mut rng) * 4.0, lcg(&mut rng) * 2.0, lcg(&mut rng) + 1.0];
            // f = 0.5 y + 0.2 (cur) and f = 2 y (ema): both perfectly linear in y.
            (y, y.map(|v| 0.5 * v + 0.2), y.map(|v| 2.0 * v))
        });
        let cfg = ReliabilitySettings { epsilon: 1e-7, ..config() };
        let (r_cur, r_ema) = reliabilities(&cfg, &m);
        assert!((r_cur - 1.0).abs() < 1e-3 && (r_ema - 1.0).abs() < 1e-3, "{r_cur} {r_ema}");
    }

    #[test]
    fn uncorrelated_stream_has_correlation_near_zero_and_anticorrelated_minus_one() {
        let mut rng = 7u64;
        let mut r_sum = 0.0;
        let mut windows = 0;
        // Average over many independent windows: one EMA window (λ = 0.9) holds ~10 samples.
        for _ in 0..100 {
            // 200 updates: the zero start has decayed (λ^200 ~ 1e-9).
            let m = run(200, |_| {
                let y = [lcg(&mut rng), lcg(&mut rng), lcg(&mut rng)];
                let f = [lcg(&mut rng), lcg(&mut rng), lcg(&mut rng)];
                (y, f, y.map(|v| 1.0 - v))
            });
            let (r_cur, r_ema) =
                reliabilities(&ReliabilitySettings { epsilon: 1e-7, ..config() }, &m);
            assert!((r_ema + 1.0).abs() < 1e-3, "anti-correlated: {r_ema}");
            r_sum += r_cur;
            windows += 1;
        }
        let mean = r_sum / windows as f32;
        assert!(mean.abs() < 0.05, "mean correlation of independent streams {mean}");
    }

    #[test]
    fn blend_weight_follows_the_reliabilities() {
        let cfg = ReliabilitySettings { epsilon: 1e-7, ..config() };
        let mut rng = 3u64;
        // cur tracks y, ema is noise: σ -> logistic(κ (1 - ~0)) close to 1/(1+e^-4).
        let m = run(300, |_| {
            let y = [lcg(&mut rng), lcg(&mut rng), lcg(&mut rng)];
            (y, y, [lcg(&mut rng), lcg(&mut rng), lcg(&mut rng)])
        });
        let (r_cur, r_ema) = reliabilities(&cfg, &m);
        let sigma = high_lr_weight(&cfg, PredictorMode::Blend, 1000, &m);
        let expected = 1.0 / (1.0 + (-4.0 * (r_cur - r_ema)).exp());
        assert!(r_cur > 0.99 && r_ema.abs() < 0.6, "{r_cur} {r_ema}");
        assert!((sigma - expected).abs() < 1e-6 && sigma > 0.85, "σ = {sigma}");
        assert_eq!(high_lr_weight(&cfg, PredictorMode::Switch, 1000, &m), 1.0);
        // The mirror image prefers EMA.
        let m3 = run(300, |_| {
            let y = [lcg(&mut rng), lcg(&mut rng), lcg(&mut rng)];
            (y, [lcg(&mut rng), lcg(&mut rng), lcg(&mut rng)], y)
        });
        let s3 = high_lr_weight(&cfg, PredictorMode::Blend, 1000, &m3);
        assert!(s3 < 0.15, "σ = {s3}");
        assert_eq!(high_lr_weight(&cfg, PredictorMode::Switch, 1000, &m3), 0.0);
        // Warm-up: markers disabled, EMA answers.
        assert_eq!(high_lr_weight(&cfg, PredictorMode::Blend, cfg.warmup - 1, &m), 0.0);
        // Equal reliabilities: an even blend.
        let (rc, re) = reliabilities(&cfg, &m);
        let mut same = m.clone();
        same.copy_within(CUR..CUR + 9, EMA);
        assert!(
            (high_lr_weight(&cfg, PredictorMode::Blend, 1000, &same) - 0.5).abs() < 1e-6,
            "{rc} {re}"
        );
        assert_eq!(combine(0.25, [4.0, 0.0, -8.0], [0.0, 4.0, -8.0]), [1.0, 3.0, 0.0]);
    }

    #[test]
    fn relative_error_sees_a_lagging_factor_the_correlation_cannot() {
        let cfg = ReliabilitySettings { epsilon: 1e-7, ..config() };
        let mut rng = 11u64;
        // The EMA predictor lags: it still answers half the light (a factor, as when a light
        // dims), the High-LR one tracks it with noise. Both correlate almost perfectly with y.
        let (mut direct_cur, mut direct_ema, mut direct_qy) =
            ([0.0f32; 3], [0.0f32; 3], [0.0f32; 3]);
        let mut streams = Vec::new();
        let m = run(300, |_| {
            let y = [lcg(&mut rng) + 0.5, lcg(&mut rng) + 0.5, lcg(&mut rng) + 0.5];
            let fc: [f32; 3] = std::array::from_fn(|c| y[c] + 0.05 * (lcg(&mut rng) - 0.5));
            let fe = y.map(|v| 0.5 * v);
            streams.push((y, fc, fe));
            (y, fc, fe)
        });
        // The same errors as EMAs of their own, sample by sample.
        for (y, fc, fe) in &streams {
            for c in 0..3 {
                direct_cur[c] = ema_step(cfg.lambda, direct_cur[c], (y[c] - fc[c]).powi(2));
                direct_ema[c] = ema_step(cfg.lambda, direct_ema[c], (y[c] - fe[c]).powi(2));
                direct_qy[c] = ema_step(cfg.lambda, direct_qy[c], y[c] * y[c]);
            }
        }
        let relative =
            |e: [f32; 3]| (0..3).map(|c| e[c] / (direct_qy[c] + cfg.epsilon)).sum::<f32>() / 3.0;
        let (e_cur, e_ema) = relative_errors(&cfg, &m);
        // f32 moments of size ~1 cancel to a difference of ~1e-3: a few ulps of 1 is the bound.
        assert!((e_cur - relative(direct_cur)).abs() < 1e-5, "{e_cur} vs {}", relative(direct_cur));
        assert!((e_ema - relative(direct_ema)).abs() < 1e-5, "{e_ema} vs {}", relative(direct_ema));
        // Half the light: (y - y/2)² / y² = 1/4 exactly, whatever y.
        assert!((e_ema - 0.25).abs() < 1e-4, "{e_ema}");
        let (r_cur, r_ema) = reliabilities(&cfg, &m);
        let paper = high_lr_weight(&cfg, PredictorMode::Blend, 1000, &m);
        let by_error = high_lr_weight(
            &cfg,
            PredictorMode::BlendBy(ReliabilityStatistic::RelativeError),
            1000,
            &m,
        );
        // Eq. 3 sees two reliable predictors (σ near 1/2); the error weighting picks High-LR.
        assert!(
            r_ema > 0.999 && r_cur > 0.95 && (paper - 0.5).abs() < 0.1,
            "{r_cur} {r_ema} σ {paper}"
        );
        let expected = (e_ema + cfg.epsilon) / (e_cur + e_ema + 2.0 * cfg.epsilon);
        assert!(by_error > 0.99 && (by_error - expected).abs() < 1e-6, "σ = {by_error}");
        assert_eq!(
            high_lr_weight(
                &cfg,
                PredictorMode::BlendBy(ReliabilityStatistic::Correlation),
                1000,
                &m
            ),
            paper
        );
        // The gain through the origin sees the factor too: ρ_EMA = 2, so σ ≈ logistic(4 ln 2).
        let (d_cur, d_ema) = scale_mismatches(&cfg, &m);
        assert!((d_ema - 2f32.ln()).abs() < 1e-4 && d_cur < 0.01, "{d_cur} {d_ema}");
        let by_scale = high_lr_weight(
            &cfg,
            PredictorMode::BlendBy(ReliabilityStatistic::ScaleRatio),
            1000,
            &m,
        );
        let expected = 1.0 / (1.0 + (-cfg.kappa * (d_ema - d_cur)).exp());
        assert!(by_scale > 0.9 && (by_scale - expected).abs() < 1e-6, "σ = {by_scale}");
        // Warm-up holds for it too, and an empty cell is an even blend.
        let warm = PredictorMode::BlendBy(ReliabilityStatistic::RelativeError);
        assert_eq!(high_lr_weight(&cfg, warm, cfg.warmup - 1, &m), 0.0);
        assert_eq!(high_lr_weight(&cfg, warm, 1000, &[0.0; MOMENTS_PER_CELL]), 0.5);
        let scale = PredictorMode::BlendBy(ReliabilityStatistic::ScaleRatio);
        assert_eq!(high_lr_weight(&cfg, scale, cfg.warmup - 1, &m), 0.0);
        assert_eq!(high_lr_weight(&cfg, scale, 1000, &[0.0; MOMENTS_PER_CELL]), 0.5);
    }

    #[test]
    fn per_sample_and_batch_mean_rules_differ_as_their_memories_say() {
        // 50 samples of targets 0..49 in one cell, in one step, from zero moments.
        let cfg = config();
        let bounds = SceneBounds::new([0.0; 3], [1.0; 3]);
        let cells = cell_count(&cfg) as usize * MOMENTS_PER_CELL;
        let batch: Vec<ReliabilitySample> = (0..50)
            .map(|i| ReliabilitySample {
                position: [0.1, 0.1, 0.1, 0.0],
                target_rgb: [i as f32, 0.0, 0.0, 0.0],
                f_cur: [0.0; 4],
                f_ema: [0.0; 4],
            })
            .collect();
        let (mut per_sample, mut batch_mean) = (vec![0.0f32; cells], vec![0.0f32; cells]);
        assert!(update(&cfg, &bounds, &mut per_sample, &batch));
        assert!(update(
            &ReliabilitySettings { update: MomentUpdate::BatchMean, ..cfg.clone() },
            &bounds,
            &mut batch_mean,
            &batch
        ));
        let cell = cell_index(&cfg, &bounds, [0.1, 0.1, 0.1]) as usize * MOMENTS_PER_CELL;
        // Per sample, the last ~10 samples dominate: 49 - λ/(1 - λ) (1 - λ^49) = 40.05.
        let expected = 49.0 - 0.9 / 0.1 * (1.0 - 0.9f32.powi(49));
        assert!((per_sample[cell] - expected).abs() < 1e-3, "{} vs {expected}", per_sample[cell]);
        // Per batch, one step of 10% towards the mean 24.5.
        assert!((batch_mean[cell] - 2.45).abs() < 1e-4, "{}", batch_mean[cell]);
        // A non-finite sample changes nothing.
        let mut bad = batch.clone();
        bad[7].f_ema[1] = f32::NAN;
        let mut untouched = per_sample.clone();
        assert!(!update(&cfg, &bounds, &mut untouched, &bad));
        assert_eq!(untouched, per_sample);
    }

    #[test]
    fn cells_follow_the_voxel_grid() {
        let cfg = config();
        let b = SceneBounds::new([-2.0; 3], [2.0; 3]);
        // Same voxel -> same cell; positions are clamped to the box.
        assert_eq!(
            cell_index(&cfg, &b, [-1.9, -1.9, -1.9]),
            cell_index(&cfg, &b, [-1.1, -1.5, -1.01])
        );
        assert_eq!(cell_index(&cfg, &b, [5.0, 5.0, 5.0]), cell_index(&cfg, &b, [1.9, 1.9, 1.9]));
        assert_eq!(cell_index(&cfg, &b, [0.5, 0.5, 0.5]), spatial_hash(2, 2, 2) & 63);
    }
}
