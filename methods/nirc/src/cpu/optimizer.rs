//! CPU reference of the optimiser step: Adam on every parameter, then the debiased EMA of the
//! weights. The powers β1^t, β2^t, α^t are carried as running products (not pow) so that the
//! GPU, which does the same multiplications, gets the same bits.

use crate::optimizer_config::{AdamSettings, EmaSettings};
use serde::{Deserialize, Serialize};

render::gpu_struct! {
    /// Step counters, the GPU's `Counters` buffer (passes that raise `flag` see it as
    /// `CountersAtomic`, see `counters_atomic_wgsl`).
    #[derive(PartialEq, Serialize, Deserialize)]
    pub struct Counters {
        /// Committed training steps t.
        pub step: u32 => "u32",
        /// Steps rolled back because a loss, gradient or weight was not finite.
        pub rejected_steps: u32 => "u32",
        /// Updates of the reliability grid (one per committed step that carried samples).
        pub grid_updates: u32 => "u32",
        /// Scratch of the step in flight on the GPU (non-finite flag); always 0 at rest.
        pub flag: u32 => "u32",
        pub beta1_pow: f32 => "f32",
        pub beta2_pow: f32 => "f32",
        pub alpha_pow: f32 => "f32",
        pub _pad: u32 => "u32",
    }
}

/// `Counters` with an atomic `flag`, for the passes that raise it (the same layout).
pub fn counters_atomic_wgsl() -> String {
    use render::gpu_struct::GpuStruct;
    Counters::WGSL.replacen("struct Counters", "struct CountersAtomic", 1).replacen(
        "flag: u32",
        "flag: atomic<u32>",
        1,
    )
}

impl Default for Counters {
    fn default() -> Self {
        Self {
            step: 0,
            rejected_steps: 0,
            grid_updates: 0,
            flag: 0,
            beta1_pow: 1.0,
            beta2_pow: 1.0,
            alpha_pow: 1.0,
            _pad: 0,
        }
    }
}

/// The powers after this step: β1^t, β2^t, α^t with t = step + 1.
pub fn next_powers(c: &Counters, adam: &AdamSettings, ema: &EmaSettings) -> (f32, f32, f32) {
    (c.beta1_pow * adam.beta1, c.beta2_pow * adam.beta2, c.alpha_pow * ema.alpha)
}

/// β_t = (1 - α) / (1 - α^t), the weight of the newest weights in the debiased EMA.
#[inline]
pub fn ema_weight(alpha: f32, alpha_pow: f32) -> f32 {
    (1.0 - alpha) / (1.0 - alpha_pow)
}

/// New (w, m, v, w̄) of one parameter for gradient g. `powers` are from `next_powers`;
/// `alpha_pow_prev` = α^{t-1}.
#[inline]
#[allow(clippy::too_many_arguments)]
pub fn adam_ema_update(
    adam: &AdamSettings,
    ema: &EmaSettings,
    powers: (f32, f32, f32),
    alpha_pow_prev: f32,
    w: f32,
    m: f32,
    v: f32,
    w_ema: f32,
    g: f32,
) -> (f32, f32, f32, f32) {
    let (b1t, b2t, at) = powers;
    let m1 = adam.beta1 * m + (1.0 - adam.beta1) * g;
    let v1 = adam.beta2 * v + (1.0 - adam.beta2) * (g * g);
    let m_hat = m1 / (1.0 - b1t);
    let v_hat = v1 / (1.0 - b2t);
    let w1 = w - adam.learning_rate * m_hat / (v_hat.sqrt() + adam.epsilon);
    // w̄_t = (α w̄_{t-1} (1 - α^{t-1}) + (1 - α) w_t) / (1 - α^t) written as the convex
    // combination w̄_{t-1} + β_t (w_t - w̄_{t-1}), β_t = (1 - α) / (1 - α^t): algebraically the
    // same, and exact on a constant sequence. At t = 1 (β = 1, α^{t-1} = 1) it is w_1 itself.
    let e1 =
        if alpha_pow_prev == 1.0 { w1 } else { w_ema + ema_weight(ema.alpha, at) * (w1 - w_ema) };
    (w1, m1, v1, e1)
}

/// Most rows a [`BiasPowers`] table may have (16 MiB on the GPU).
const MAX_BIAS_ROWS: usize = 1 << 20;

/// The powers (β1^t, β2^t, α^t, 0) for each per-entry step count t of sparse grid updates, as
/// running products from t = 0: the multiplications `Counters` does, so an entry that steps
/// every step gets the dense step's bits. The table ends at the first t where every 1 − power is
/// exactly 1.0 in f32; a larger count reads the last row, whose bias corrections are then the
/// same (tiny-cuda-nn computes powf(β, t) per parameter instead, which the CPU and GPU need not
/// round alike).
#[derive(Clone, Debug, PartialEq)]
pub struct BiasPowers {
    pub rows: Vec<[f32; 4]>,
}

impl BiasPowers {
    pub fn new(adam: &AdamSettings, ema: &EmaSettings) -> Result<Self, crate::NircError> {
        let mut rows = vec![[1.0f32, 1.0, 1.0, 0.0]];
        loop {
            let last = *rows.last().expect("one row");
            if last[..3].iter().all(|&p| 1.0 - p == 1.0) {
                return Ok(Self { rows });
            }
            if rows.len() >= MAX_BIAS_ROWS {
                return Err(crate::NircError::Config(format!(
                    "optimizer.sparse_grid: β1 = {}, β2 = {}, ema.alpha = {} need more than {} \
                     per-entry bias corrections (a β this close to 1 never settles)",
                    adam.beta1, adam.beta2, ema.alpha, MAX_BIAS_ROWS
                )));
            }
            rows.push([last[0] * adam.beta1, last[1] * adam.beta2, last[2] * ema.alpha, 0.0]);
        }
    }

    /// (β1^t, β2^t, α^t).
    pub fn at(&self, t: u32) -> (f32, f32, f32) {
        let r = self.rows[(t as usize).min(self.rows.len() - 1)];
        (r[0], r[1], r[2])
    }
}

/// One hash-grid parameter under sparse updates: `None` (nothing changes, its step count
/// included) where the gradient is exactly zero; else its new (w, m, v, w̄) and step count, Adam
/// and the EMA debiased with the parameter's own count t (tiny-cuda-nn's per-parameter steps).
#[inline]
#[allow(clippy::too_many_arguments)]
pub fn sparse_adam_ema_update(
    adam: &AdamSettings,
    ema: &EmaSettings,
    table: &BiasPowers,
    steps: u32,
    w: f32,
    m: f32,
    v: f32,
    w_ema: f32,
    g: f32,
) -> Option<((f32, f32, f32, f32), u32)> {
    if g == 0.0 {
        return None;
    }
    let t = steps + 1;
    Some((adam_ema_update(adam, ema, table.at(t), table.at(t - 1).2, w, m, v, w_ema, g), t))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn bias_power_rows_are_the_dense_running_products_until_they_settle() {
        let (adam, ema) = (AdamSettings::default(), EmaSettings::default());
        let table = BiasPowers::new(&adam, &ema).unwrap();
        let mut c = Counters::default();
        for t in 0..table.rows.len() as u32 + 50 {
            let (b1, b2, a) = table.at(t);
            // Bit for bit the dense step's powers while the table lasts; past it, the same bias
            // corrections (1 - power is 1.0 in both).
            if (t as usize) < table.rows.len() {
                assert_eq!((b1, b2, a), (c.beta1_pow, c.beta2_pow, c.alpha_pow), "t={t}");
            } else {
                assert_eq!((1.0 - b1, 1.0 - b2, 1.0 - a), (1.0, 1.0, 1.0), "t={t}");
                assert_eq!(
                    (1.0 - c.beta1_pow, 1.0 - c.beta2_pow, 1.0 - c.alpha_pow),
                    (1.0, 1.0, 1.0)
                );
            }
            (c.beta1_pow, c.beta2_pow, c.alpha_pow) = next_powers(&c, &adam, &ema);
        }
        // 0.99^t < 2^-25 from t = 1725 on: the table is about that long, not a fitted length.
        assert!((1700..1760).contains(&table.rows.len()), "{}", table.rows.len());
        let close = AdamSettings { beta2: 0.9999999, ..adam };
        assert!(BiasPowers::new(&close, &ema).is_err());
    }

    #[test]
    fn debiased_ema_of_a_constant_sequence_is_the_constant() {
        let adam = AdamSettings::default();
        for alpha in [0.5f32, 0.9, 0.99, 0.999] {
            let ema = EmaSettings { alpha };
            let w = 0.737_f32;
            // The first debiased value is w_1 itself whatever the initial w̄.
            let mut e = 123.0f32;
            let mut c = Counters::default();
            for t in 1..=2000 {
                let powers = next_powers(&c, &adam, &ema);
                // g = 0 with m = v = 0 keeps w fixed, so the EMA sees a constant sequence.
                let (w1, _, _, e1) =
                    adam_ema_update(&adam, &ema, powers, c.alpha_pow, w, 0.0, 0.0, e, 0.0);
                assert_eq!(w1, w);
                assert_eq!(e1, w, "α={alpha} t={t}");
                e = e1;
                c.step = t;
                (c.beta1_pow, c.beta2_pow, c.alpha_pow) = powers;
            }
        }
    }

    #[test]
    fn debiased_ema_matches_the_plain_average_form() {
        // w̄_t equals (Σ_s (1-α) α^{t-s} w_s) / (1 - α^t): check in f64 against the update in f32.
        let ema = EmaSettings { alpha: 0.9 };
        let adam = AdamSettings::default();
        let ws: Vec<f32> = (0..50).map(|i| (i as f32 * 0.37).sin()).collect();
        let mut e = 0.0f32;
        let mut c = Counters::default();
        for (t, &w) in ws.iter().enumerate() {
            let powers = next_powers(&c, &adam, &ema);
            e = adam_ema_update(&adam, &ema, powers, c.alpha_pow, w, 0.0, 0.0, e, 0.0).3;
            c.step += 1;
            (c.beta1_pow, c.beta2_pow, c.alpha_pow) = powers;
            let a = 0.9f64;
            let num: f64 = ws[..=t]
                .iter()
                .enumerate()
                .map(|(s, &x)| (1.0 - a) * a.powi((t - s) as i32) * x as f64)
                .sum();
            let expected = num / (1.0 - a.powi(t as i32 + 1));
            assert!((e as f64 - expected).abs() < 1e-5, "t={t}: {e} vs {expected}");
        }
    }
}
