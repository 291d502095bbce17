//! Sparse grid updates (`optimizer.sparse_grid`, tiny-cuda-nn's Adam): the CPU twin's rules, and
//! the GPU's passes over the touched quads against it.

mod common;

use common::*;
use nirc::config::{HashGridSettings, PredictorMode};
use nirc::cpu::encoding::grid_corners;
use nirc::gpu::shaders::WeightPlacement;
use nirc::{CacheState, CpuCache, NeuralCache, NircCacheSettings, TrainingRecord};
use render::gpu::Gpu;
use std::collections::BTreeSet;
use std::sync::OnceLock;

fn gpu() -> &'static Gpu {
    static GPU: OnceLock<Gpu> = OnceLock::new();
    GPU.get_or_init(|| Gpu::new().expect("a wgpu adapter (lavapipe on CI)"))
}

fn sparse(mut config: NircCacheSettings) -> NircCacheSettings {
    config.optimizer.sparse_grid = true;
    config
}

/// Records in the box [0.2, 0.6] x [0, 0.4] x [-1.5, -0.5] of the bounds, so that the finer
/// levels have entries no record reaches.
fn corner_records(rng: &mut Rng, n: usize) -> Vec<TrainingRecord> {
    (0..n)
        .map(|_| {
            let p = [rng.range(0.2, 0.6), rng.range(0.0, 0.4), rng.range(-1.5, -0.5)];
            let d = rng.direction();
            TrainingRecord::new(p, d, field(p, d))
        })
        .collect()
}

/// Grid parameters (relative to the grid's first) that some record of `batch` reaches with a
/// non-zero trilinear weight: the only ones whose gradient can be non-zero.
fn reached(state: &CacheState, batch: &[TrainingRecord]) -> BTreeSet<usize> {
    let layout = state.layout();
    let f = layout.features_per_level as usize;
    let mut out = BTreeSet::new();
    for r in batch {
        let corners = grid_corners(
            &layout,
            state.bounds.normalize([r.position[0], r.position[1], r.position[2]]),
        );
        for level in &corners {
            for c in 0..8 {
                if level.weight[c] != 0.0 {
                    for k in 0..f {
                        out.insert(level.param_index[c] as usize + k - layout.mlp_params as usize);
                    }
                }
            }
        }
    }
    out
}

/// The CPU twin: a parameter no record reaches keeps its weight, moments, EMA weight and step
/// count bit for bit; one that every step reaches counts every step.
#[test]
fn cpu_sparse_steps_skip_unreached_entries_and_count_the_others() {
    let config = sparse(small_config());
    let state = randomized_state(&config, 3);
    let batch = corner_records(&mut Rng(4), 64);
    let reached = reached(&state, &batch);
    let grid = state.layout().mlp_params as usize;
    let total = state.grid_steps.len();
    assert!(
        reached.len() > 50 && reached.len() < total / 2,
        "the test needs both kinds of entry ({} of {total} reached)",
        reached.len()
    );
    let mut cpu = CpuCache::new(state.clone());
    const STEPS: u32 = 5;
    for _ in 0..STEPS {
        assert!(cpu.train_step(&batch).committed);
    }
    let s = &cpu.state;
    for i in 0..total {
        let p = grid + i;
        if reached.contains(&i) {
            // A sum of products of non-zero values is zero only by accident.
            assert_eq!(s.grid_steps[i], STEPS, "parameter {i}");
            assert_ne!(s.params[p], state.params[p], "parameter {i}");
        } else {
            assert_eq!(s.grid_steps[i], 0, "parameter {i}");
            assert_eq!(
                (s.params[p], s.adam_m[p], s.adam_v[p], s.ema[p]),
                (state.params[p], state.adam_m[p], state.adam_v[p], state.ema[p]),
                "parameter {i}"
            );
        }
    }
    // The MLP is dense: its weights move as in any step.
    assert!(
        s.params[..grid].iter().zip(&state.params[..grid]).filter(|(a, b)| a != b).count()
            > grid / 2
    );
}

/// A grid every record reaches everywhere (two levels of one cell, 8 vertices each): every
/// grid parameter steps every step, so sparse updates are dense Adam, bit for bit.
fn reached_everywhere() -> NircCacheSettings {
    NircCacheSettings {
        encoding: HashGridSettings {
            levels: 2,
            features_per_level: 2,
            log2_table_size: 10,
            base_resolution: 1,
            growth_factor: 1.0,
            init_scale: 1e-4,
        },
        ..small_config()
    }
}

#[test]
fn cpu_sparse_steps_equal_dense_adam_when_every_entry_is_reached() {
    let dense_config = reached_everywhere();
    let state = randomized_state(&dense_config, 8);
    let mut dense = CpuCache::new(state.clone());
    let mut sparse_cache = CpuCache::new(CacheState {
        grid_steps: vec![0; state.layout().grid_params() as usize],
        config: sparse(dense_config),
        ..state
    });
    let mut rng = Rng(9);
    for _ in 0..20 {
        let batch = records(&mut rng, 40);
        assert!(dense.train_step(&batch).committed);
        assert!(sparse_cache.train_step(&batch).committed);
    }
    let (d, s) = (&dense.state, &sparse_cache.state);
    assert_eq!(s.params, d.params);
    assert_eq!(s.ema, d.ema);
    assert_eq!((&s.adam_m, &s.adam_v), (&d.adam_m, &d.adam_v));
    assert!(s.grid_steps.iter().all(|&t| t == 20), "{:?}", s.grid_steps);
}

fn close(a: f32, b: f32, rel: f32, abs: f32) -> bool {
    (a - b).abs() <= rel * a.abs().max(b.abs()) + abs
}

fn assert_vec_close(what: &str, gpu: &[f32], cpu: &[f32], rel: f32, abs: f32) {
    assert_eq!(gpu.len(), cpu.len(), "{what}: lengths");
    let bad: Vec<_> = (0..gpu.len()).filter(|&i| !close(gpu[i], cpu[i], rel, abs)).collect();
    assert!(
        bad.is_empty(),
        "{what}: {} of {} values differ, first: {:?}",
        bad.len(),
        gpu.len(),
        bad.iter().take(6).map(|&i| (i, gpu[i], cpu[i])).collect::<Vec<_>>()
    );
}

/// The GPU's passes over the touched quads against the CPU twin: twelve steps of batches in one
/// corner of the scene and then elsewhere (entries touched in some steps only), in both
/// training forms; step counts equal exactly, unreached entries are untouched bit for bit, the
/// rest as close as the dense twelve-step test (tests/gpu.rs).
#[test]
fn gpu_sparse_steps_match_the_cpu_twin() {
    let config = sparse(small_config());
    let state = randomized_state(&config, 51);
    for placement in [WeightPlacement::Registers, WeightPlacement::Storage] {
        let mut cpu = CpuCache::new(state.clone());
        let cache = NeuralCache::from_state(gpu(), &state, Some(placement)).unwrap();
        let mut rng = Rng(52);
        let mut all_reached = BTreeSet::new();
        for step in 0..12 {
            let batch =
                if step < 8 { corner_records(&mut rng, 130) } else { records(&mut rng, 20) };
            all_reached.extend(reached(&cpu.state, &batch));
            assert!(cpu.train_step(&batch).committed);
            cache.train_records(gpu(), &batch).unwrap();
        }
        let got = cache.download_state(gpu()).unwrap();
        assert_eq!(got.counters, cpu.state.counters, "{placement:?}");
        assert_eq!(got.grid_steps, cpu.state.grid_steps, "{placement:?}: step counts");
        let counts: BTreeSet<u32> = got.grid_steps.iter().copied().collect();
        assert!(counts.len() >= 4, "{placement:?}: the test needs varied counts, {counts:?}");
        let grid = state.layout().mlp_params as usize;
        let unreached = (0..got.grid_steps.len()).filter(|i| !all_reached.contains(i));
        for i in unreached {
            let p = grid + i;
            assert_eq!(
                (got.params[p], got.adam_m[p], got.adam_v[p], got.ema[p]),
                (state.params[p], state.adam_m[p], state.adam_v[p], state.ema[p]),
                "{placement:?}: unreached parameter {i}"
            );
        }
        let lr = config.optimizer.learning_rate;
        assert_vec_close("params", &got.params, &cpu.state.params, 1e-4, 2e-2 * lr);
        assert_vec_close("ema", &got.ema, &cpu.state.ema, 1e-4, 2e-2 * lr);
        assert_vec_close("adam m", &got.adam_m, &cpu.state.adam_m, 1e-3, 1e-9);
        // The register form reads the grid from its texture mirror: the sparse passes keep it.
        let q: Vec<_> = records(&mut rng, 100).iter().map(|r| r.query()).collect();
        for mode in [PredictorMode::EmaOnly, PredictorMode::HighLrOnly] {
            for (g, w) in
                cache.infer_queries(gpu(), &q, mode).unwrap().iter().zip(cpu.infer(&q, mode))
            {
                for c in 0..3 {
                    assert!(
                        close(g.radiance[c], w.radiance[c], 1e-3, 1e-4),
                        "{placement:?} {mode:?}: {:?} vs {:?}",
                        g.radiance,
                        w.radiance
                    );
                }
            }
        }
        // The step counts survive a save and a load.
        let tmp = tempfile::tempdir().unwrap();
        let path = tmp.path().join(format!("nirc-sparse-{placement:?}.nirc"));
        got.save(&path).unwrap();
        assert_eq!(CacheState::load(&path).unwrap(), got);
    }
}

/// On the GPU too, sparse updates on a grid every record reaches are the dense step.
#[test]
fn gpu_sparse_steps_equal_dense_steps_when_every_entry_is_reached() {
    let dense_config = reached_everywhere();
    let state = randomized_state(&dense_config, 8);
    let sparse_state = CacheState {
        grid_steps: vec![0; state.layout().grid_params() as usize],
        config: sparse(dense_config),
        ..state.clone()
    };
    let dense = NeuralCache::from_state(gpu(), &state, Some(WeightPlacement::Tiled)).unwrap();
    let sparse_cache =
        NeuralCache::from_state(gpu(), &sparse_state, Some(WeightPlacement::Tiled)).unwrap();
    let mut rng = Rng(9);
    for _ in 0..12 {
        let batch = records(&mut rng, 40);
        dense.train_records(gpu(), &batch).unwrap();
        sparse_cache.train_records(gpu(), &batch).unwrap();
    }
    let (d, s) =
        (dense.download_state(gpu()).unwrap(), sparse_cache.download_state(gpu()).unwrap());
    assert!(s.grid_steps.iter().all(|&t| t == 12), "{:?}", s.grid_steps);
    // The same arithmetic on the same values; 1e-6 relative leaves room for a compiler that
    // fuses the two passes' multiply-adds differently.
    assert_vec_close("params", &s.params, &d.params, 1e-6, 0.0);
    assert_vec_close("ema", &s.ema, &d.ema, 1e-6, 0.0);
    assert_vec_close("adam m", &s.adam_m, &d.adam_m, 1e-6, 0.0);
    assert_vec_close("adam v", &s.adam_v, &d.adam_v, 1e-6, 0.0);
}

/// Sparse steps give the same bits twice (as the dense ones do: the gradient sums are
/// fixed-point and the touched list is in ascending order, whatever the threads' order).
#[test]
fn gpu_sparse_steps_are_deterministic() {
    let config = sparse(small_config());
    let state = randomized_state(&config, 61);
    let run = || {
        let cache = NeuralCache::from_state(gpu(), &state, Some(WeightPlacement::Tiled)).unwrap();
        let mut rng = Rng(62);
        for step in 0..6 {
            let batch =
                if step < 4 { corner_records(&mut rng, 130) } else { records(&mut rng, 40) };
            cache.train_records(gpu(), &batch).unwrap();
        }
        (cache.download_state(gpu()).unwrap(), cache.touched_grid_quads(gpu()).unwrap())
    };
    let (a, touched_a) = run();
    let (b, touched_b) = run();
    assert!(touched_a > 0);
    assert_eq!(touched_a, touched_b);
    let bits = |v: &[f32]| v.iter().map(|x| x.to_bits()).collect::<Vec<_>>();
    assert_eq!(a.grid_steps, b.grid_steps);
    assert!(bits(&a.params) == bits(&b.params), "params differ between two runs");
    assert!(bits(&a.ema) == bits(&b.ema), "EMA differs between two runs");
    assert!(bits(&a.adam_m) == bits(&b.adam_m) && bits(&a.adam_v) == bits(&b.adam_v));
}
