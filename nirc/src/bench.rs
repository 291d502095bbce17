//! Throughput benchmark of the GPU cache (not a test): training and inference queries per
//! second and GFLOP/s, and the cost of evaluating both predictors + blend over EMA-only.

use crate::config::{NircConfig, PredictorMode};
use crate::error::NircError;
use crate::gpu::shaders::WeightPlacement;
use crate::gpu::{NeuralCache, answer_buffer, readback, upload};
use crate::records::{CacheQuery, TrainingRecord};
use crate::state::CacheState;
use crate::bounds::SceneBounds;
use render::gpu::Gpu;
use std::time::Instant;

#[derive(Clone, Debug)]
pub struct BenchReport {
    pub adapter: String,
    pub placement: WeightPlacement,
    pub width: u32,
    pub hidden_layers: u32,
    pub batch: u32,
    pub queries: u32,
    pub train_records_per_s: f64,
    /// MLP FLOPs of training counted as 3 forwards (forward, backward, weight gradient) of the
    /// High-LR predictor + 1 forward of the EMA predictor, per record.
    pub train_gflops: f64,
    pub ema_only_queries_per_s: f64,
    pub blend_queries_per_s: f64,
    pub ema_only_gflops: f64,
    pub blend_gflops: f64,
    /// Extra time of blend over EMA-only, in percent of EMA-only.
    pub blend_overhead_percent: f64,
}

fn records(n: u32) -> Vec<TrainingRecord> {
    let mut s = 0x1234_5678u32;
    let mut rnd = || {
        s ^= s << 13;
        s ^= s >> 17;
        s ^= s << 5;
        s as f32 / u32::MAX as f32
    };
    (0..n)
        .map(|_| {
            let p = [rnd(), rnd(), rnd()];
            let d = glam::Vec3::new(rnd() - 0.5, rnd() - 0.5, rnd() - 0.5).normalize_or(glam::Vec3::Z);
            TrainingRecord::new(p, d.into(), [p[0], p[1] * p[2], 0.5])
        })
        .collect()
}

fn time<F: FnMut() -> Result<(), NircError>>(gpu: &Gpu, reps: u32, mut f: F) -> Result<f64, NircError> {
    f()?; // warm-up (pipeline compilation, first touch)
    readback::wait_idle(gpu)?;
    let t = Instant::now();
    for _ in 0..reps {
        f()?;
    }
    readback::wait_idle(gpu)?;
    Ok(t.elapsed().as_secs_f64() / reps as f64)
}

/// Runs the benchmark with `config` (e.g. width 64) on `batch` training records and `queries`
/// queries, `reps` repetitions each.
pub fn run(gpu: &Gpu, config: &NircConfig, placement: Option<WeightPlacement>, batch: u32, queries: u32, reps: u32) -> Result<BenchReport, NircError> {
    let mut config = config.clone();
    config.max_batch = config.max_batch.max(batch);
    // Warm-up 0 so that the blend really reads the reliability grid.
    config.reliability.warmup = 0;
    let state = CacheState::initial(&config, SceneBounds::new([0.0; 3], [1.0; 3]))?;
    let cache = NeuralCache::from_state(gpu, &state, placement)?;
    let recs = upload(gpu, "bench records", &records(batch));
    let train_s = time(gpu, reps, || cache.train(gpu, &recs, batch))?;
    let q: Vec<CacheQuery> = records(queries).iter().map(|r| r.query()).collect();
    let qbuf = upload(gpu, "bench queries", &q);
    let out = answer_buffer(gpu, queries);
    let ema_s = time(gpu, reps, || cache.infer(gpu, &qbuf, queries, &out, PredictorMode::EmaOnly))?;
    let blend_s = time(gpu, reps, || cache.infer(gpu, &qbuf, queries, &out, PredictorMode::Blend))?;
    let flops = 2.0 * cache.layout.forward_macs() as f64;
    Ok(BenchReport {
        adapter: gpu.summary.to_string(),
        placement: cache.placement,
        width: config.network.width,
        hidden_layers: config.network.hidden_layers,
        batch,
        queries,
        train_records_per_s: batch as f64 / train_s,
        train_gflops: batch as f64 * 4.0 * flops / train_s / 1e9,
        ema_only_queries_per_s: queries as f64 / ema_s,
        blend_queries_per_s: queries as f64 / blend_s,
        ema_only_gflops: queries as f64 * flops / ema_s / 1e9,
        blend_gflops: queries as f64 * 2.0 * flops / blend_s / 1e9,
        blend_overhead_percent: 100.0 * (blend_s - ema_s) / ema_s,
    })
}
