//! The WGSL passes against the CPU reference, on the adapter (lavapipe on CI): forward, one
//! training step, the reliability grid, save/load exactness, rollback of a non-finite step.

mod common;

use common::*;
use nirc::config::{PredictorMode, ReliabilityStatistic};
use nirc::gpu::shaders::WeightPlacement;
use nirc::gpu::upload;
use nirc::{CacheState, CpuCache, NeuralCache, ReliabilitySample};
use render::gpu::Gpu;
use std::sync::OnceLock;

fn gpu() -> &'static Gpu {
    static GPU: OnceLock<Gpu> = OnceLock::new();
    GPU.get_or_init(|| Gpu::new().expect("a wgpu adapter (lavapipe on CI)"))
}

fn close(a: f32, b: f32, rel: f32, abs: f32) -> bool {
    (a - b).abs() <= rel * a.abs().max(b.abs()) + abs
}

fn assert_vec_close(what: &str, gpu: &[f32], cpu: &[f32], rel: f32, abs: f32) {
    assert_eq!(gpu.len(), cpu.len(), "{what}: lengths");
    let mut bad = Vec::new();
    for (i, (g, c)) in gpu.iter().zip(cpu).enumerate() {
        if !close(*g, *c, rel, abs) {
            bad.push((i, *g, *c));
        }
    }
    assert!(
        bad.is_empty(),
        "{what}: {} of {} values differ, first: {:?}",
        bad.len(),
        gpu.len(),
        &bad[..bad.len().min(8)]
    );
}

#[test]
fn forward_matches_cpu_in_every_weight_placement() {
    let config = small_config();
    let state = randomized_state(&config, 21);
    let cpu = CpuCache::new(state.clone());
    let mut rng = Rng(4);
    let queries: Vec<_> = records(&mut rng, 200).iter().map(|r| r.query()).collect();
    for placement in [WeightPlacement::Tiled, WeightPlacement::Storage, WeightPlacement::Registers]
    {
        let cache = NeuralCache::from_state(gpu(), &state, Some(placement)).unwrap();
        assert_eq!(cache.placement, placement);
        // Two features per level: the register form reads the grid from its texture mirror
        // (lavapipe and the GPUs the lab runs on have rgba32float storage textures).
        assert_eq!(
            cache.reads_grid_mirror(),
            placement == WeightPlacement::Registers,
            "{placement:?}"
        );
        for mode in [
            PredictorMode::HighLrOnly,
            PredictorMode::EmaOnly,
            PredictorMode::Blend,
            PredictorMode::Switch,
            PredictorMode::Fixed(0.3),
        ] {
            let got = cache.infer_queries(gpu(), &queries, mode).unwrap();
            let want = cpu.infer(&queries, mode);
            let mut nonzero = 0;
            for (g, w) in got.iter().zip(&want) {
                assert!(
                    close(g.sigma, w.sigma, 1e-5, 1e-6),
                    "{placement:?} {mode:?}: sigma {} vs {}",
                    g.sigma,
                    w.sigma
                );
                for c in 0..3 {
                    assert!(
                        close(g.radiance[c], w.radiance[c], 1e-4, 1e-6),
                        "{placement:?} {mode:?}: {:?} vs {:?}",
                        g.radiance,
                        w.radiance
                    );
                    nonzero += (w.radiance[c] > 1e-3) as usize;
                }
            }
            assert!(nonzero > 100, "the test needs non-trivial outputs ({nonzero})");
        }
    }
}

/// With other than two features per level the register form reads the grid from the parameter
/// buffers (no texture mirror), and still trains and infers as the CPU does.
#[test]
fn register_form_without_the_grid_mirror_matches_cpu() {
    let mut config = small_config();
    config.encoding.features_per_level = 1;
    let state = randomized_state(&config, 31);
    let mut cpu = CpuCache::new(state.clone());
    let cache = NeuralCache::from_state(gpu(), &state, Some(WeightPlacement::Registers)).unwrap();
    assert!(!cache.reads_grid_mirror());
    let mut rng = Rng(32);
    let queries: Vec<_> = records(&mut rng, 200).iter().map(|r| r.query()).collect();
    let batch = records(&mut rng, 100);
    // Before the step the two predictors differ (after the first step the debiased EMA equals
    // the weights), and after it the step's writes must be read.
    for trained in [false, true] {
        if trained {
            assert!(cpu.train_step(&batch).committed);
            cache.train_records(gpu(), &batch).unwrap();
        }
        for mode in [PredictorMode::EmaOnly, PredictorMode::HighLrOnly, PredictorMode::Blend] {
            let (got, want) =
                (cache.infer_queries(gpu(), &queries, mode).unwrap(), cpu.infer(&queries, mode));
            for (g, w) in got.iter().zip(&want) {
                for c in 0..3 {
                    assert!(
                        close(g.radiance[c], w.radiance[c], 1e-4, 1e-6),
                        "trained {trained}, {mode:?}: {:?} vs {:?}",
                        g.radiance,
                        w.radiance
                    );
                }
            }
        }
    }
}

/// The register form (one query per invocation, weights in a uniform buffer) sums every layer
/// in the tiled form's order, so its answers match the tiled form's far closer than the CPU
/// tolerance (on lavapipe they are bit-identical); with the default network (width 64, the
/// paper's) as well as the small one. Both ways of recording an inference are checked, each
/// after a training step changed the weights: the register form stages them per inference.
#[test]
fn register_form_matches_the_tiled_form() {
    for config in [small_config(), nirc::NircCacheSettings { max_batch: 256, ..Default::default() }]
    {
        let state = randomized_state(&config, 31);
        let batch = records(&mut Rng(6), 128);
        let queries: Vec<_> = records(&mut Rng(5), 150).iter().map(|r| r.query()).collect();
        let tiled = NeuralCache::from_state(gpu(), &state, Some(WeightPlacement::Tiled)).unwrap();
        let lane =
            NeuralCache::from_state(gpu(), &state, Some(WeightPlacement::Registers)).unwrap();
        // Every mode: one predictor, both blended (three ways), or both switched.
        for mode in [
            PredictorMode::EmaOnly,
            PredictorMode::Blend,
            PredictorMode::HighLrOnly,
            PredictorMode::Switch,
            PredictorMode::Fixed(0.3),
        ] {
            lane.infer_queries(gpu(), &queries, mode).unwrap();
            tiled.train_records(gpu(), &batch).unwrap();
            lane.train_records(gpu(), &batch).unwrap();
            let a = tiled.infer_queries(gpu(), &queries, mode).unwrap();
            let b = if mode == PredictorMode::Blend {
                infer_timed(&lane, &queries, mode)
            } else {
                lane.infer_queries(gpu(), &queries, mode).unwrap()
            };
            for (t, l) in a.iter().zip(&b) {
                assert_eq!(t.sigma, l.sigma, "width {} {mode:?}", config.network.width);
                for c in 0..3 {
                    assert!(
                        close(l.radiance[c], t.radiance[c], 1e-6, 1e-7),
                        "width {} {mode:?}: {:?} vs {:?}",
                        config.network.width,
                        l.radiance,
                        t.radiance
                    );
                }
            }
        }
    }
}

/// `infer_timed`, the way a scenario's frame records an inference.
fn infer_timed(
    cache: &NeuralCache,
    queries: &[nirc::records::CacheQuery],
    mode: PredictorMode,
) -> Vec<nirc::records::CacheAnswer> {
    let qbuf = nirc::gpu::upload(gpu(), "queries", queries);
    let out = nirc::gpu::answer_buffer(gpu(), queries.len() as u32);
    let timer = render::timing::PassTimer::wall(&["infer"]);
    let mut frame = timer.begin(gpu(), "infer");
    cache.infer_timed(gpu(), &mut frame, 0, &qbuf, queries.len() as u32, &out, mode).unwrap();
    frame.submit().unwrap();
    nirc::gpu::read_answers(gpu(), &out, queries.len() as u32).unwrap()
}

#[test]
fn one_training_step_matches_cpu() {
    let config = small_config();
    let state = randomized_state(&config, 33);
    let mut rng = Rng(6);
    // 300 records: four full weight-gradient chunks (training tiles of 64) and a partial one.
    let batch = records(&mut rng, 300);
    let mut cpu = CpuCache::new(state.clone());
    let report = cpu.train_step(&batch);
    assert!(report.committed);
    for placement in [WeightPlacement::Tiled, WeightPlacement::Storage] {
        let cache = NeuralCache::from_state(gpu(), &state, Some(placement)).unwrap();
        cache.train_records(gpu(), &batch).unwrap();
        let got = cache.download_state(gpu()).unwrap();
        assert_eq!(got.counters, cpu.state.counters, "{placement:?}");
        let loss = cache.last_loss(gpu(), batch.len() as u32).unwrap();
        assert!((loss - report.loss).abs() <= 1e-5 * report.loss, "loss {loss} vs {}", report.loss);
        let lr = config.optimizer.learning_rate;
        // First Adam step moves each weight by about lr; compare to a small fraction of it.
        assert_vec_close("params", &got.params, &cpu.state.params, 1e-5, 1e-3 * lr);
        assert_vec_close("ema", &got.ema, &cpu.state.ema, 1e-5, 1e-3 * lr);
        assert_vec_close("adam m", &got.adam_m, &cpu.state.adam_m, 1e-3, 1e-9);
        assert_vec_close("adam v", &got.adam_v, &cpu.state.adam_v, 2e-3, 1e-12);
        assert_vec_close("reliability", &got.reliability, &cpu.state.reliability, 1e-4, 1e-6);
        // The step really moved the weights.
        let moved = got
            .params
            .iter()
            .zip(&state.params)
            .filter(|(a, b)| (*a - *b).abs() > 0.5 * lr)
            .count();
        assert!(moved > got.params.len() / 10, "only {moved} parameters moved");
    }
}

#[test]
fn twelve_steps_keep_weights_ema_and_blend_on_the_cpu_reference() {
    // Step 1's debiased EMA equals the weights; only later steps test the average itself.
    let config = small_config();
    let state = randomized_state(&config, 51);
    let mut rng = Rng(52);
    let mut cpu = CpuCache::new(state.clone());
    let cache = NeuralCache::from_state(gpu(), &state, Some(WeightPlacement::Tiled)).unwrap();
    for _ in 0..12 {
        let batch = records(&mut rng, 130);
        assert!(cpu.train_step(&batch).committed);
        cache.train_records(gpu(), &batch).unwrap();
    }
    let got = cache.download_state(gpu()).unwrap();
    assert_eq!(got.counters, cpu.state.counters);
    let lr = config.optimizer.learning_rate;
    // Twelve Adam steps of about lr each: round-off compounds, the bound is still far below lr.
    assert_vec_close("params", &got.params, &cpu.state.params, 1e-4, 2e-2 * lr);
    assert_vec_close("ema", &got.ema, &cpu.state.ema, 1e-4, 2e-2 * lr);
    let apart = got.ema.iter().zip(&got.params).filter(|(e, p)| (*e - *p).abs() > lr).count();
    assert!(
        apart > got.ema.len() / 10,
        "after 12 steps the EMA must lag the weights ({apart} apart)"
    );
    let q: Vec<_> = records(&mut rng, 100).iter().map(|r| r.query()).collect();
    for mode in [PredictorMode::EmaOnly, PredictorMode::Blend] {
        for (g, w) in cache.infer_queries(gpu(), &q, mode).unwrap().iter().zip(cpu.infer(&q, mode))
        {
            assert!(close(g.sigma, w.sigma, 1e-3, 1e-4), "{mode:?}: σ {} vs {}", g.sigma, w.sigma);
            for c in 0..3 {
                assert!(
                    close(g.radiance[c], w.radiance[c], 1e-3, 1e-4),
                    "{mode:?}: {:?} vs {:?}",
                    g.radiance,
                    w.radiance
                );
            }
        }
    }
}

#[test]
fn reliability_grid_matches_cpu_on_a_random_stream() {
    // 64 cells for 400 samples a step: ~6 samples per cell, spread over several 64-sample
    // chunks (the per-sample walk orders each cell's list by selection).
    reliability_stream(nirc::config::MomentUpdate::PerSample, 4, 6);
    reliability_stream(nirc::config::MomentUpdate::BatchMean, 4, 6);
}

#[test]
fn crowded_reliability_cells_match_cpu() {
    // At most 4 cells for 400 samples: k² > n, so the walk scans the batch instead.
    reliability_stream(nirc::config::MomentUpdate::PerSample, 2, 2);
}

fn reliability_stream(rule: nirc::config::MomentUpdate, resolution: u32, log2_cells: u32) {
    let mut config = small_config();
    config.reliability.warmup = 3;
    config.reliability.resolution = resolution;
    config.reliability.log2_cells = log2_cells;
    config.reliability.update = rule;
    let state = CacheState::initial(&config, bounds()).unwrap();
    let cache = NeuralCache::from_state(gpu(), &state, None).unwrap();
    let mut moments = state.reliability.clone();
    let mut rng = Rng(77);
    let b = bounds();
    for update in 0..6 {
        let samples: Vec<ReliabilitySample> = (0..400)
            .map(|_| {
                let p = [
                    rng.range(b.min[0], b.max[0]),
                    rng.range(b.min[1], b.max[1]),
                    rng.range(b.min[2], b.max[2]),
                ];
                let y = [rng.range(0.0, 3.0), rng.range(0.0, 1.0), rng.range(0.0, 0.1)];
                // cur tracks y, ema lags with noise: distinct correlations per cell.
                let fc = y.map(|v| 0.9 * v + 0.1);
                let fe = [rng.range(0.0, 3.0), y[1] * 0.5, rng.range(0.0, 0.1)];
                ReliabilitySample {
                    position: [p[0], p[1], p[2], 0.0],
                    target_rgb: [y[0], y[1], y[2], 0.0],
                    f_cur: [fc[0], fc[1], fc[2], 0.0],
                    f_ema: [fe[0], fe[1], fe[2], 0.0],
                }
            })
            .collect();
        assert!(nirc::reliability::update(&config.reliability, &b, &mut moments, &samples));
        cache
            .update_reliability(gpu(), &upload(gpu(), "samples", &samples), samples.len() as u32)
            .unwrap();
        let got = cache.download_state(gpu()).unwrap();
        assert_vec_close(
            &format!("{rule:?} moments after update {update}"),
            &got.reliability,
            &moments,
            1e-5,
            1e-7,
        );
        assert_eq!(got.counters.grid_updates, update + 1);
    }
    if log2_cells < 6 {
        return; // too few cells for the answers below to differ between cells
    }
    // Blend and switch answers follow the CPU reliabilities (warm-up over).
    let cpu = CpuCache::new(CacheState {
        reliability: moments,
        counters: cache.counters(gpu()).unwrap(),
        ..state
    });
    let queries: Vec<_> = records(&mut rng, 300).iter().map(|r| r.query()).collect();
    for mode in [PredictorMode::Blend, PredictorMode::Switch] {
        let got = cache.infer_queries(gpu(), &queries, mode).unwrap();
        let want = cpu.infer(&queries, mode);
        let mut off_half = 0;
        for (g, w) in got.iter().zip(&want) {
            assert!(close(g.sigma, w.sigma, 1e-4, 1e-5), "{mode:?}: σ {} vs {}", g.sigma, w.sigma);
            off_half += ((w.sigma - 0.5).abs() > 0.2) as usize;
        }
        assert!(off_half > 100, "{mode:?}: the reliabilities must decide ({off_half})");
    }
    // The blends by the other statistics: σ and the blended radiance as the CPU's, and each a
    // statistic of its own (not eq. 3's σ again).
    let paper = cpu.infer(&queries, PredictorMode::Blend);
    for statistic in [ReliabilityStatistic::RelativeError, ReliabilityStatistic::ScaleRatio] {
        let by_error = PredictorMode::BlendBy(statistic);
        let mut differs = 0;
        for ((g, w), p) in cache
            .infer_queries(gpu(), &queries, by_error)
            .unwrap()
            .iter()
            .zip(cpu.infer(&queries, by_error))
            .zip(&paper)
        {
            assert!(
                close(g.sigma, w.sigma, 1e-4, 1e-5),
                "{by_error:?}: σ {} vs {}",
                g.sigma,
                w.sigma
            );
            for c in 0..3 {
                assert!(
                    close(g.radiance[c], w.radiance[c], 1e-4, 1e-6),
                    "{:?} vs {:?}",
                    g.radiance,
                    w.radiance
                );
            }
            // 10x the σ tolerance above: a different statistic, not rounding.
            differs += ((w.sigma - p.sigma).abs() > 1e-3) as usize;
        }
        assert!(differs > 150, "{statistic:?} gives eq. 3's σ ({differs} of 300 differ)");
    }
    // The fixed blend ignores the grid: σ is the setting, the radiance the blend of both.
    let fixed = PredictorMode::Fixed(0.3);
    for (g, w) in
        cache.infer_queries(gpu(), &queries, fixed).unwrap().iter().zip(cpu.infer(&queries, fixed))
    {
        assert_eq!((g.sigma, w.sigma), (0.3, 0.3));
        for c in 0..3 {
            assert!(
                close(g.radiance[c], w.radiance[c], 1e-4, 1e-6),
                "{:?} vs {:?}",
                g.radiance,
                w.radiance
            );
        }
    }
}

#[test]
fn save_load_reproduces_the_next_step_and_inference_exactly() {
    let config = small_config();
    let mut rng = Rng(12);
    let cache = NeuralCache::new(gpu(), &config, bounds()).unwrap();
    for _ in 0..3 {
        cache.train_records(gpu(), &records(&mut rng, 200)).unwrap();
    }
    let tmp = tempfile::tempdir().unwrap();
    let dir = tmp.path().to_path_buf();
    std::fs::create_dir_all(&dir).unwrap();
    let path = dir.join("warm.nirc");
    cache.save(gpu(), &path).unwrap();
    let loaded = NeuralCache::load(gpu(), &path).unwrap();
    assert_eq!(loaded.download_state(gpu()).unwrap(), cache.download_state(gpu()).unwrap());
    let next = records(&mut rng, 200);
    cache.train_records(gpu(), &next).unwrap();
    loaded.train_records(gpu(), &next).unwrap();
    let a = cache.download_state(gpu()).unwrap();
    let b = loaded.download_state(gpu()).unwrap();
    // Bit-exact: the state and the answers, in every mode.
    assert_eq!(a.params, b.params);
    assert_eq!(a.ema, b.ema);
    assert_eq!(a.adam_m, b.adam_m);
    assert_eq!(a.adam_v, b.adam_v);
    assert_eq!(a.reliability, b.reliability);
    assert_eq!(a.counters, b.counters);
    let q: Vec<_> = next.iter().map(|r| r.query()).collect();
    for mode in [
        PredictorMode::EmaOnly,
        PredictorMode::HighLrOnly,
        PredictorMode::Blend,
        PredictorMode::Switch,
    ] {
        assert_eq!(
            cache.infer_queries(gpu(), &q, mode).unwrap(),
            loaded.infer_queries(gpu(), &q, mode).unwrap(),
            "{mode:?}"
        );
    }
}

#[test]
fn nan_target_rolls_the_step_back_and_is_counted() {
    let config = small_config();
    let mut rng = Rng(13);
    let cache = NeuralCache::new(gpu(), &config, bounds()).unwrap();
    cache.train_records(gpu(), &records(&mut rng, 128)).unwrap();
    let before = cache.download_state(gpu()).unwrap();
    let mut bad = records(&mut rng, 128);
    bad[77].target_rgb[2] = f32::NAN;
    cache.train_records(gpu(), &bad).unwrap();
    let after = cache.download_state(gpu()).unwrap();
    assert_eq!(after.params, before.params);
    assert_eq!(after.ema, before.ema);
    assert_eq!(after.adam_m, before.adam_m);
    assert_eq!(after.adam_v, before.adam_v);
    assert_eq!(after.reliability, before.reliability);
    assert_eq!(after.counters.rejected_steps, 1);
    assert_eq!(after.counters.step, before.counters.step);
    assert_eq!(after.counters.flag, 0);
    // The CPU reference agrees, and training goes on afterwards.
    let mut cpu = CpuCache::new(before.clone());
    assert!(!cpu.train_step(&bad).committed);
    cache.train_records(gpu(), &records(&mut rng, 128)).unwrap();
    let c = cache.counters(gpu()).unwrap();
    assert_eq!((c.step, c.rejected_steps), (before.counters.step + 1, 1));
}

#[test]
fn other_encodings_widths_and_loss_normalisation_match_cpu() {
    use nirc::config::{DirectionEncoding, LossNormalization, NetworkSettings};
    let variants = [
        (
            DirectionEncoding::Identity,
            LossNormalization::Luminance,
            NetworkSettings { width: 32, hidden_layers: 1 },
        ),
        (
            DirectionEncoding::None,
            LossNormalization::PerChannel,
            NetworkSettings { width: 16, hidden_layers: 3 },
        ),
        // An odd width: the MLP's weights end inside a quad, so the layout pads before the grid.
        (
            DirectionEncoding::Identity,
            LossNormalization::PerChannel,
            NetworkSettings { width: 5, hidden_layers: 1 },
        ),
    ];
    for (direction, normalization, network) in variants {
        let mut config = small_config();
        config.direction = direction;
        config.loss.normalization = normalization;
        config.network = network.clone();
        let state = randomized_state(&config, 44);
        let mut rng = Rng(45);
        let batch = records(&mut rng, 100);
        let mut cpu = CpuCache::new(state.clone());
        assert!(cpu.train_step(&batch).committed);
        let cache = NeuralCache::from_state(gpu(), &state, None).unwrap();
        cache.train_records(gpu(), &batch).unwrap();
        let got = cache.download_state(gpu()).unwrap();
        let what = format!("{direction:?} {normalization:?} {network:?}");
        let layout = state.layout();
        if network.width == 5 {
            assert_ne!(
                layout.mlp_weights() % 4,
                0,
                "{what}: the case must leave a gap before the grid"
            );
        }
        // The quad padding (after the matrices, after the grid tables) stays zero.
        let grid_end = (layout.mlp_params + layout.grid_table_params()) as usize;
        let padding = (layout.mlp_weights() as usize..layout.mlp_params as usize)
            .chain(grid_end..layout.total_params as usize);
        for i in padding {
            assert_eq!(
                (got.params[i], got.ema[i], got.adam_m[i]),
                (0.0, 0.0, 0.0),
                "{what}: padding parameter {i}"
            );
        }
        let lr = config.optimizer.learning_rate;
        assert_vec_close(
            &format!("{what} params"),
            &got.params,
            &cpu.state.params,
            1e-5,
            1e-3 * lr,
        );
        assert_vec_close(&format!("{what} adam m"), &got.adam_m, &cpu.state.adam_m, 1e-3, 1e-9);
        let q: Vec<_> = batch.iter().map(|r| r.query()).collect();
        let (g, w) = (
            cache.infer_queries(gpu(), &q, PredictorMode::HighLrOnly).unwrap(),
            cpu.infer(&q, PredictorMode::HighLrOnly),
        );
        for (a, b) in g.iter().zip(&w) {
            for c in 0..3 {
                assert!(
                    close(a.radiance[c], b.radiance[c], 1e-4, 1e-6),
                    "{what}: {:?} vs {:?}",
                    a.radiance,
                    b.radiance
                );
            }
        }
    }
}

#[test]
fn refuses_oversized_batches_and_short_buffers_clearly() {
    let config = small_config();
    let cache = NeuralCache::new(gpu(), &config, bounds()).unwrap();
    let mut rng = Rng(1);
    let err = cache.train_records(gpu(), &records(&mut rng, 513)).unwrap_err().to_string();
    assert!(err.contains("513") && err.contains("max_batch"), "{err}");
    let recs = upload(gpu(), "few", &records(&mut rng, 4));
    let err = cache.train(gpu(), &recs, 8).unwrap_err().to_string();
    assert!(err.contains("training records") && err.contains("8 items"), "{err}");
}

#[test]
fn steps_recorded_in_one_encoder_equal_separate_submissions() {
    let config = small_config();
    let state = randomized_state(&config, 55);
    let mut rng = Rng(56);
    let (b1, b2) = (records(&mut rng, 150), records(&mut rng, 90));
    let q: Vec<_> = records(&mut rng, 64).iter().map(|r| r.query()).collect();
    let separate = NeuralCache::from_state(gpu(), &state, None).unwrap();
    separate.train_records(gpu(), &b1).unwrap();
    separate.train_records(gpu(), &b2).unwrap();
    let want = separate.infer_queries(gpu(), &q, PredictorMode::Blend).unwrap();

    let together = NeuralCache::from_state(gpu(), &state, None).unwrap();
    let (r1, r2, qb) = (upload(gpu(), "b1", &b1), upload(gpu(), "b2", &b2), upload(gpu(), "q", &q));
    let out = nirc::gpu::answer_buffer(gpu(), q.len() as u32);
    let mut encoder = gpu().device.create_command_encoder(&Default::default());
    together.encode_train(gpu(), &mut encoder, &r1, b1.len() as u32).unwrap();
    together.encode_train(gpu(), &mut encoder, &r2, b2.len() as u32).unwrap();
    together
        .encode_infer(gpu(), &mut encoder, &qb, q.len() as u32, &out, PredictorMode::Blend)
        .unwrap();
    gpu().queue.submit([encoder.finish()]);
    let got: Vec<nirc::CacheAnswer> = render::readback::read_pod(gpu(), &out, "answers").unwrap();
    assert_eq!(&got[..q.len()], &want[..]);
    assert_eq!(together.download_state(gpu()).unwrap(), separate.download_state(gpu()).unwrap());
}

#[test]
fn gpu_training_converges_like_the_cpu_reference() {
    let config = small_config();
    let gpu_cache = NeuralCache::new(gpu(), &config, bounds()).unwrap();
    let mut cpu = CpuCache::new(CacheState::initial(&config, bounds()).unwrap());
    let mut rng = Rng(321);
    let mut first = None;
    let (mut gpu_loss, mut cpu_loss) = (0.0, 0.0);
    for _ in 0..150 {
        let batch = records(&mut rng, 256);
        gpu_cache.train_records(gpu(), &batch).unwrap();
        gpu_loss = gpu_cache.last_loss(gpu(), 256).unwrap();
        cpu_loss = cpu.train_step(&batch).loss;
        first.get_or_insert(gpu_loss);
    }
    let first = first.unwrap();
    eprintln!("GPU loss {first} -> {gpu_loss}, CPU loss at the last step {cpu_loss}");
    assert!(gpu_loss < first / 1000.0, "GPU loss {first} -> {gpu_loss}");
    // 150 steps apart, the two implementations still train alike (round-off only).
    assert!((gpu_loss - cpu_loss).abs() < 0.1 * cpu_loss, "GPU {gpu_loss} vs CPU {cpu_loss}");
    assert_eq!(gpu_cache.counters(gpu()).unwrap().step, 150);
}

#[test]
fn networks_the_tiled_mlp_does_not_take_fall_back_to_storage_or_are_refused() {
    let small = NeuralCache::new(gpu(), &small_config(), bounds()).unwrap();
    // On a CPU adapter (lavapipe) the default is the register-form inference, else the tiled.
    let expected = if gpu().summary.device_type == "Cpu" {
        WeightPlacement::Registers
    } else {
        WeightPlacement::Tiled
    };
    assert_eq!(small.placement, expected);
    assert!(nirc::gpu::shaders::workgroup_bytes(&small.layout) <= 32768);
    let default = nirc::layout::ParameterLayout::new(&nirc::NircCacheSettings::default());
    assert_eq!(nirc::gpu::shaders::workgroup_bytes(&default), 32768, "width 64: two 16 KiB tiles");
    let mut config = small_config();
    config.network = nirc::config::NetworkSettings { width: 128, hidden_layers: 2 };
    let big = NeuralCache::new(gpu(), &config, bounds()).unwrap();
    assert_eq!(big.placement, WeightPlacement::Storage);
    let state = CacheState::initial(&config, bounds()).unwrap();
    let err = NeuralCache::from_state(gpu(), &state, Some(WeightPlacement::Tiled))
        .err()
        .expect("refused")
        .to_string();
    assert!(err.contains("tiled MLP") && err.contains("width 128"), "{err}");
    let err = NeuralCache::from_state(gpu(), &state, Some(WeightPlacement::Registers))
        .err()
        .expect("refused")
        .to_string();
    assert!(err.contains("width 128"), "{err}");
    // The fallback computes the same thing.
    let cpu = CpuCache::new(state);
    let q: Vec<_> = records(&mut Rng(9), 32).iter().map(|r| r.query()).collect();
    let got = big.infer_queries(gpu(), &q, PredictorMode::EmaOnly).unwrap();
    for (g, w) in got.iter().zip(cpu.infer(&q, PredictorMode::EmaOnly)) {
        for c in 0..3 {
            assert!(close(g.radiance[c], w.radiance[c], 1e-4, 1e-7));
        }
    }
}

#[test]
fn networks_over_the_drivers_loop_cap_are_refused() {
    let mut config = small_config();
    // Forward alone: 128 x 128 x 4 + ... ~ 72k multiply-adds per query, over llvmpipe's 65535.
    config.network = nirc::config::NetworkSettings { width: 128, hidden_layers: 5 };
    let result = NeuralCache::new(gpu(), &config, bounds());
    match gpu().loop_iteration_limit() {
        Some(limit) => {
            let err = result.err().expect("refused on a driver with a loop cap").to_string();
            assert!(
                err.contains("loop iterations")
                    && err.contains(&limit.to_string())
                    && err.contains("width 128"),
                "{err}"
            );
        }
        None => assert!(result.is_ok(), "no loop cap on this adapter, yet refused"),
    }
    // The defaults (width 64) stay well inside the cap.
    let default = nirc::layout::ParameterLayout::new(&nirc::NircCacheSettings::default());
    assert!(default.loop_iterations_per_invocation(64) < render::gpu::LLVMPIPE_LOOP_ITERATIONS / 2);
}

/// `flicker bench --nirc` profiles a training step stage by stage: every dispatch of the step is
/// named once, in the step's order, in both weight placements (the tiled train pass writes the
/// gradient partials itself; the per-record form has a pass for them), and each stage runs alone without error.
#[test]
fn training_profile_names_every_stage_of_a_step_once() {
    let config = small_config();
    let state = randomized_state(&config, 5);
    let recs = records(&mut Rng(9), 128);
    let buf = upload(gpu(), "profile records", &recs);
    for placement in [WeightPlacement::Tiled, WeightPlacement::Storage] {
        let cache = NeuralCache::from_state(gpu(), &state, Some(placement)).unwrap();
        let stages = cache.train_stage_seconds(gpu(), &buf, recs.len() as u32, 1).unwrap();
        let names: Vec<&str> = stages.iter().map(|s| s.0).collect();
        let mut expected = vec!["train (forward, backward)", "reliability accumulate"];
        if placement == WeightPlacement::Storage {
            expected.push("weight gradient partials");
        }
        expected.extend([
            "weight gradient reduce",
            "adam check (every parameter)",
            "adam apply (every parameter)",
            "ema update (every parameter)",
        ]);
        expected.extend([
            "reliability walk",
            "reliability update",
            "finish step",
            "clear the step's accumulators",
        ]);
        assert_eq!(names, expected, "{placement:?}");
        assert!(stages.iter().all(|s| s.1.is_finite() && s.1 >= 0.0), "{stages:?}");
    }
}
