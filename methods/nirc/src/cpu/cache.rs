//! CPU reference of a whole training step and of inference, mirroring the GPU passes (same
//! summation orders: MLP weight gradients summed per chunk of `GRADIENT_CHUNK` records and then
//! over chunks; hash-grid gradients and reliability moments summed as exact fixed-point).

use super::encoding::encode;
use super::loss::{denominators, relative_l2};
use super::mlp::{Activations, backward, forward};
use super::optimizer::{BiasPowers, adam_ema_update, next_powers, sparse_adam_ema_update};
use super::real::Real;
use crate::config::{NircCacheSettings, PredictorMode};
use crate::fixed_sum::FixedSum;
use crate::layout::ParameterLayout;
use crate::records::{CacheAnswer, CacheQuery, ReliabilitySample, TrainingRecord};
use crate::reliability::{self, MOMENTS_PER_CELL};
use crate::state::CacheState;

/// Records per partial sum of the MLP weight gradient (the GPU's chunk).
pub const GRADIENT_CHUNK: usize = 64;

/// What a training step did.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct StepReport {
    /// Mean relative L2 loss of the batch before the step (NaN if a target was not finite).
    pub loss: f64,
    /// False if the step was rolled back (non-finite loss, gradient or weight).
    pub committed: bool,
}

pub struct CpuCache {
    pub state: CacheState,
    pub layout: ParameterLayout,
}

fn xyz(v: [f32; 4]) -> [f32; 3] {
    [v[0], v[1], v[2]]
}

/// Forward of one query through the network with parameters `params`.
pub fn predict<T: Real>(
    config: &NircCacheSettings,
    layout: &ParameterLayout,
    params: &[T],
    state: &CacheState,
    q: &CacheQuery,
) -> ([T; 3], Activations<T>, Vec<crate::cpu::encoding::LevelCorners>) {
    let (input, corners) =
        encode(layout, config.direction, params, &state.bounds, xyz(q.position), xyz(q.direction));
    let acts = forward(layout, params, input);
    (acts.output, acts, corners)
}

impl CpuCache {
    pub fn new(state: CacheState) -> Self {
        let layout = state.layout();
        Self { state, layout }
    }

    /// Prediction of the High-LR (`ema = false`) or EMA weights, before any clamp.
    pub fn predict(&self, q: &CacheQuery, ema: bool) -> [f32; 3] {
        let params = if ema { &self.state.ema } else { &self.state.params };
        predict(&self.state.config, &self.layout, params, &self.state, q).0
    }

    pub fn infer(&self, queries: &[CacheQuery], mode: PredictorMode) -> Vec<CacheAnswer> {
        let cfg = &self.state.config.reliability;
        queries
            .iter()
            .map(|q| {
                let cell =
                    reliability::cell_index(cfg, &self.state.bounds, xyz(q.position)) as usize;
                let moments =
                    &self.state.reliability[cell * MOMENTS_PER_CELL..(cell + 1) * MOMENTS_PER_CELL];
                let sigma = reliability::high_lr_weight(
                    cfg,
                    mode,
                    self.state.counters.grid_updates,
                    moments,
                );
                let f_ema = if mode == PredictorMode::HighLrOnly {
                    [0.0; 3]
                } else {
                    self.predict(q, true)
                };
                let f_cur =
                    if mode == PredictorMode::EmaOnly { [0.0; 3] } else { self.predict(q, false) };
                CacheAnswer { radiance: reliability::combine(sigma, f_cur, f_ema), sigma }
            })
            .collect()
    }

    /// Mean loss and its gradient (w.r.t. every parameter) of a batch in precision T, with the
    /// loss denominators frozen at `denominators` (stop-gradient) if given. For gradient checks.
    pub fn loss_and_gradient<T: Real>(
        &self,
        params: &[T],
        records: &[TrainingRecord],
        frozen: Option<&[[T; 3]]>,
    ) -> (T, Vec<T>) {
        let cfg = &self.state.config;
        let mut grad = vec![T::zero(); params.len()];
        let mut total = T::zero();
        let inv_n = T::from_f32(1.0) / T::from_f32(records.len() as f32);
        for (r, rec) in records.iter().enumerate() {
            let (f, acts, corners) = predict(cfg, &self.layout, params, &self.state, &rec.query());
            let den = frozen.map(|d| d[r]).unwrap_or_else(|| denominators(&cfg.loss, f));
            let (loss, d_out) = relative_l2(f, xyz(rec.target_rgb).map(T::from_f32), den);
            total += loss * inv_n;
            let (deltas, d_input) = backward(&self.layout, params, &acts, d_out.map(|d| d * inv_n));
            for (k, m) in self.layout.matrices.iter().enumerate() {
                for i in 0..m.rows as usize {
                    for j in 0..m.cols as usize {
                        grad[m.offset as usize + i * m.cols as usize + j] +=
                            deltas[k][i] * acts.layers[k][j];
                    }
                }
            }
            self.scatter_grid(&corners, &d_input, |index, g| grad[index] += g);
        }
        (total, grad)
    }

    /// Distributes dL/d(feature) to the 8 table entries of every level.
    fn scatter_grid<T: Real>(
        &self,
        corners: &[crate::cpu::encoding::LevelCorners],
        d_input: &[T],
        mut add: impl FnMut(usize, T),
    ) {
        let f = self.layout.features_per_level as usize;
        for (l, level) in corners.iter().enumerate() {
            for c in 0..8 {
                for k in 0..f {
                    add(
                        level.param_index[c] as usize + k,
                        T::from_f32(level.weight[c]) * d_input[l * f + k],
                    );
                }
            }
        }
    }

    /// One training step on a batch, as the GPU does it; rolled back if anything is not finite.
    pub fn train_step(&mut self, records: &[TrainingRecord]) -> StepReport {
        let cfg = self.state.config.clone();
        let layout = &self.layout;
        let n = records.len();
        if n == 0 {
            return StepReport { loss: 0.0, committed: false };
        }
        let mut finite = true;
        let mut loss_sum = 0.0f64;
        let mut acts_all = Vec::with_capacity(n);
        let mut deltas_all = Vec::with_capacity(n);
        let mut samples = Vec::with_capacity(n);
        let grid_base = layout.mlp_params as usize;
        let mut grid_sums = vec![FixedSum::default(); layout.grid_params() as usize];
        for rec in records {
            let q = rec.query();
            let (f, acts, corners) = predict(&cfg, layout, &self.state.params, &self.state, &q);
            let f_ema = self.predict(&q, true);
            let y = xyz(rec.target_rgb);
            let (loss, d_out) = relative_l2(f, y, denominators(&cfg.loss, f));
            finite &= loss.is_finite();
            loss_sum += loss as f64;
            let (deltas, d_input) = backward(layout, &self.state.params, &acts, d_out);
            self.scatter_grid(&corners, &d_input, |index, g| {
                finite &= grid_sums[index - grid_base].add(g)
            });
            samples.push(ReliabilitySample {
                position: rec.position,
                target_rgb: rec.target_rgb,
                f_cur: [f[0], f[1], f[2], 0.0],
                f_ema: [f_ema[0], f_ema[1], f_ema[2], 0.0],
            });
            acts_all.push(acts);
            deltas_all.push(deltas);
        }
        let inv_n = 1.0 / n as f32;
        let mut grad = vec![0.0f32; layout.total_params as usize];
        for (k, m) in layout.matrices.iter().enumerate() {
            for i in 0..m.rows as usize {
                for j in 0..m.cols as usize {
                    let mut g = 0.0f32;
                    for chunk in (0..n).step_by(GRADIENT_CHUNK) {
                        let mut partial = 0.0f32;
                        for r in chunk..(chunk + GRADIENT_CHUNK).min(n) {
                            partial += deltas_all[r][k][i] * acts_all[r].layers[k][j];
                        }
                        g += partial;
                    }
                    grad[m.offset as usize + i * m.cols as usize + j] = g * inv_n;
                }
            }
        }
        for (i, s) in grid_sums.iter().enumerate() {
            grad[grid_base + i] = s.to_f32() * inv_n;
        }
        finite &= grad.iter().all(|g| g.is_finite());
        let st = &mut self.state;
        let powers = next_powers(&st.counters, &cfg.optimizer, &cfg.ema);
        // Sparse grid updates: a grid parameter with a zero gradient keeps (w, m, v, w̄) and its
        // step count; the others step with their own counts. The MLP is dense either way.
        let table = cfg
            .optimizer
            .sparse_grid
            .then(|| BiasPowers::new(&cfg.optimizer, &cfg.ema).expect("validated config"));
        let mut updated = Vec::with_capacity(grad.len());
        let mut steps = st.grid_steps.clone();
        if finite {
            for (i, &g) in grad.iter().enumerate() {
                let (w, m, v, e) = (st.params[i], st.adam_m[i], st.adam_v[i], st.ema[i]);
                let u = match &table {
                    Some(table) if i >= grid_base => {
                        let t = &mut steps[i - grid_base];
                        match sparse_adam_ema_update(
                            &cfg.optimizer,
                            &cfg.ema,
                            table,
                            *t,
                            w,
                            m,
                            v,
                            e,
                            g,
                        ) {
                            Some((u, next)) => {
                                *t = next;
                                u
                            }
                            None => (w, m, v, e),
                        }
                    }
                    _ => adam_ema_update(
                        &cfg.optimizer,
                        &cfg.ema,
                        powers,
                        st.counters.alpha_pow,
                        w,
                        m,
                        v,
                        e,
                        g,
                    ),
                };
                finite &= u.0.is_finite() && u.1.is_finite() && u.2.is_finite() && u.3.is_finite();
                updated.push(u);
            }
        }
        let mut moments = st.reliability.clone();
        finite =
            finite && reliability::update(&cfg.reliability, &st.bounds, &mut moments, &samples);
        if !finite {
            st.counters.rejected_steps += 1;
            return StepReport { loss: loss_sum / n as f64, committed: false };
        }
        for (i, (w, m, v, e)) in updated.into_iter().enumerate() {
            (st.params[i], st.adam_m[i], st.adam_v[i], st.ema[i]) = (w, m, v, e);
        }
        st.reliability = moments;
        st.grid_steps = steps;
        st.counters.step += 1;
        st.counters.grid_updates += 1;
        (st.counters.beta1_pow, st.counters.beta2_pow, st.counters.alpha_pow) = powers;
        StepReport { loss: loss_sum / n as f64, committed: true }
    }
}
