//! Tests of the CPU reference: analytic gradients against finite differences, convergence on a
//! known smooth function, save/load, rollback of a non-finite step.

mod common;

use common::*;
use nirc::cpu::loss::denominators;
use nirc::{CacheState, CpuCache, PredictorMode};

#[test]
fn gradients_match_central_finite_differences() {
    let config = small_config();
    let cache = CpuCache::new(randomized_state(&config, 11));
    let mut rng = Rng(5);
    let recs = records(&mut rng, 6);
    let params: Vec<f64> = cache.state.params.iter().map(|&w| w as f64).collect();
    // Stop-gradient: the denominators are constants of the loss, frozen at the current point.
    let frozen: Vec<[f64; 3]> = recs
        .iter()
        .map(|r| denominators(&config.loss, cache.predict(&r.query(), false).map(|v| v as f64)))
        .collect();
    let (_, grad) = cache.loss_and_gradient(&params, &recs, Some(&frozen));
    let mlp = cache.layout.mlp_params as usize;
    // Every MLP weight, and every grid entry some record touches.
    let touched: Vec<usize> = (0..params.len()).filter(|&i| i < mlp || grad[i] != 0.0).collect();
    assert!(touched.len() > mlp + 50, "records touch {} grid entries", touched.len() - mlp);
    // The loss is quadratic in any single parameter while no ReLU changes state, so a large step
    // has no truncation error and little round-off.
    let h = 1e-4;
    let mut worst = 0.0f64;
    let mut checked_grid = 0;
    for &i in &touched {
        let mut plus = params.clone();
        plus[i] += h;
        let mut minus = params.clone();
        minus[i] -= h;
        let fd = (cache.loss_and_gradient(&plus, &recs, Some(&frozen)).0
            - cache.loss_and_gradient(&minus, &recs, Some(&frozen)).0)
            / (2.0 * h);
        let err = (fd - grad[i]).abs() / (grad[i].abs() + 1e-7);
        worst = worst.max(err);
        assert!(
            err < 1e-4,
            "parameter {i} ({}): analytic {} vs finite difference {fd}",
            if i < mlp { "MLP" } else { "grid" },
            grad[i]
        );
        checked_grid += (i >= mlp) as usize;
    }
    assert!(checked_grid > 50);
    // The f32 gradient (what training uses) agrees with the f64 one.
    let (_, g32) = cache.loss_and_gradient(&cache.state.params, &recs, None);
    let (_, g64) = cache.loss_and_gradient(&params, &recs, None);
    let scale = g64.iter().fold(0.0f64, |m, g| m.max(g.abs()));
    for (a, b) in g32.iter().zip(&g64) {
        assert!((*a as f64 - b).abs() <= 1e-4 * scale, "f32 {a} vs f64 {b}");
    }
    eprintln!("worst relative gradient error {worst:.2e} over {} parameters", touched.len());
}

#[test]
fn regression_on_a_smooth_function_converges() {
    // Several EMA windows (1 / (1 - 0.99) = 100 steps), so that the EMA has caught up.
    const STEPS: u32 = 600;
    let config = small_config();
    let mut cache = CpuCache::new(CacheState::initial(&config, bounds()).unwrap());
    let mut rng = Rng(99);
    let test = records(&mut rng, 256);
    let test_loss = |c: &CpuCache| {
        let (l, _) = c.loss_and_gradient(&c.state.params, &test, None);
        l
    };
    let before = test_loss(&cache);
    for _ in 0..STEPS {
        let batch = records(&mut rng, 128);
        assert!(cache.train_step(&batch).committed);
    }
    let after = test_loss(&cache);
    assert!(after < before / 100.0, "relative L2 on held-out points: {before} -> {after}");
    // The EMA predictor learnt the field too.
    let mean_error = |c: &CpuCache, ema: bool| {
        test.iter()
            .map(|r| {
                let f = c.predict(&r.query(), ema);
                (0..3).map(|k| (f[k] - r.target_rgb[k]).abs() / r.target_rgb[k]).sum::<f32>() / 3.0
            })
            .sum::<f32>()
            / test.len() as f32
    };
    let (cur_err, ema_err) = (mean_error(&cache, false), mean_error(&cache, true));
    eprintln!("loss {before} -> {after}; mean relative error High-LR {cur_err}, EMA {ema_err}");
    assert!(cur_err < 0.05, "High-LR mean relative error {cur_err}");
    assert!(ema_err < 0.05, "EMA mean relative error {ema_err}");
    assert_eq!(cache.state.counters.step, STEPS);
}

#[test]
fn non_finite_target_rolls_the_step_back() {
    let config = small_config();
    let mut cache = CpuCache::new(CacheState::initial(&config, bounds()).unwrap());
    let mut rng = Rng(3);
    cache.train_step(&records(&mut rng, 64));
    let before = cache.state.clone();
    let mut bad = records(&mut rng, 64);
    bad[17].target_rgb[1] = f32::NAN;
    let report = cache.train_step(&bad);
    assert!(!report.committed && report.loss.is_nan());
    assert_eq!(cache.state.params, before.params);
    assert_eq!(cache.state.ema, before.ema);
    assert_eq!(cache.state.reliability, before.reliability);
    assert_eq!(cache.state.counters.rejected_steps, 1);
    assert_eq!(cache.state.counters.step, before.counters.step);
    bad[17].target_rgb[1] = f32::INFINITY;
    assert!(!cache.train_step(&bad).committed);
    assert_eq!(cache.state.counters.rejected_steps, 2);
    assert!(cache.train_step(&records(&mut rng, 64)).committed);
}

#[test]
fn saved_state_loads_identically_and_bad_files_are_refused() {
    let config = small_config();
    let mut cache = CpuCache::new(CacheState::initial(&config, bounds()).unwrap());
    let mut rng = Rng(8);
    for _ in 0..3 {
        cache.train_step(&records(&mut rng, 100));
    }
    let tmp = tempfile::tempdir().unwrap();
    let dir = tmp.path().to_path_buf();
    std::fs::create_dir_all(&dir).unwrap();
    let path = dir.join("state.nirc");
    cache.state.save(&path).unwrap();
    let loaded = CacheState::load(&path).unwrap();
    assert_eq!(loaded, cache.state);
    let mut twin = CpuCache::new(loaded);
    let next = records(&mut rng, 100);
    cache.train_step(&next);
    twin.train_step(&next);
    assert_eq!(twin.state, cache.state);
    let q: Vec<_> = next.iter().map(|r| r.query()).collect();
    assert_eq!(twin.infer(&q, PredictorMode::Blend), cache.infer(&q, PredictorMode::Blend));
    // Truncated and foreign files name the file and the problem.
    let bytes = std::fs::read(&path).unwrap();
    std::fs::write(&path, &bytes[..bytes.len() - 3]).unwrap();
    let err = CacheState::load(&path).unwrap_err().to_string();
    assert!(err.contains("state.nirc") && err.contains("truncated"), "{err}");
    std::fs::write(&path, b"not a cache").unwrap();
    let err = CacheState::load(&path).unwrap_err().to_string();
    assert!(err.contains("FLKNIRC1"), "{err}");
}
