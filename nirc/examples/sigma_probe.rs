//! Probe: the reliability-weighted blend's σ on the CPU twin of the cache (a static scene with
//! noisy Monte Carlo-like targets, nirc/tests/reliability_behaviour.rs's set-up) against the
//! number of training steps before it is read (the pre-training length), and how the
//! candidates for a σ near 1/2 move it: the moment update (per sample, the paper's, or once per
//! step towards the step's mean), ε of eq. 3, λ, and the target noise. One cache is trained;
//! every variant's moments follow the same samples (y, f_cur, f_EMA before each step), so the
//! variants differ only in their statistic. Prints mean σ and (r̄_cur, r̄_EMA) over 500 queries.
//!
//! `cargo run -p nirc --example sigma_probe -- [STEPS,...] [SEEDS,...] [NOISE]`
//! (defaults: 160,320,640,1280 steps; seeds 2024,2025,2026; noise 0.3: targets times
//! U[1 − n, 1 + n]).
//!
//! `cargo run -p nirc --example sigma_probe -- --state FILE.nirc`: a saved cache state (a run's
//! warm start, `nirc/<key>.nirc` under its cache dir) instead: over the cells that hold samples,
//! the mean per-cell σ and r̄ of eq. 3 at the state's ε and at ε = 1e-8, and the median cell's
//! M^y, s^y and s^f_EMA (the radiance scale ε meets).

use nirc::config::{
    DirectionEncoding, HashGridConfig, MomentUpdate, NetworkConfig, ReliabilityConfig,
};
use nirc::reliability::{self, MOMENTS_PER_CELL};
use nirc::{CacheQuery, TrainingRecord};
use nirc::{CacheState, CpuCache, NircConfig, PredictorMode, ReliabilitySample, SceneBounds};

struct Rng(u64);
impl Rng {
    fn f32(&mut self) -> f32 {
        self.0 = self.0.wrapping_mul(6364136223846793005).wrapping_add(1442695040888963407);
        ((self.0 >> 40) as f32) / (1u64 << 24) as f32
    }
    fn range(&mut self, lo: f32, hi: f32) -> f32 {
        lo + (hi - lo) * self.f32()
    }
    fn direction(&mut self) -> [f32; 3] {
        loop {
            let v = [self.range(-1.0, 1.0), self.range(-1.0, 1.0), self.range(-1.0, 1.0)];
            let l = (v[0] * v[0] + v[1] * v[1] + v[2] * v[2]).sqrt();
            if l > 0.1 && l <= 1.0 {
                return v.map(|x| x / l);
            }
        }
    }
}

fn bounds() -> SceneBounds {
    SceneBounds::new([-1.0, -0.5, -2.0], [3.0, 1.5, 2.0])
}

fn field(p: [f32; 3], d: [f32; 3]) -> [f32; 3] {
    [
        1.0 + 0.5 * (1.3 * p[0]).sin() * (0.7 * p[2]).cos(),
        0.6 + 0.3 * p[1] + 0.1 * d[2],
        0.2 + 0.15 * (p[0] + p[2]).cos(),
    ]
}

fn records(rng: &mut Rng, n: usize, noise: f32) -> Vec<TrainingRecord> {
    let b = bounds();
    (0..n)
        .map(|_| {
            let p = std::array::from_fn(|a| rng.range(b.min[a], b.max[a]));
            let d = rng.direction();
            let k = 1.0 - noise + 2.0 * noise * rng.f32();
            TrainingRecord::new(p, d, field(p, d).map(|v| v * k))
        })
        .collect()
}

fn config() -> NircConfig {
    NircConfig {
        encoding: HashGridConfig {
            levels: 4,
            features_per_level: 2,
            log2_table_size: 10,
            base_resolution: 4,
            growth_factor: 1.5,
            init_scale: 1e-4,
        },
        direction: DirectionEncoding::SphericalHarmonics { bands: 3 },
        network: NetworkConfig { width: 32, hidden_layers: 2 },
        reliability: ReliabilityConfig {
            resolution: 4,
            log2_cells: 6,
            warmup: 32,
            ..Default::default()
        },
        max_batch: 512,
        ..Default::default()
    }
}

fn list<T: std::str::FromStr>(arg: Option<String>, default: &[T]) -> Vec<T>
where
    T: Clone,
{
    arg.map(|a| a.split(',').map(|v| v.parse().ok().expect("a number")).collect())
        .unwrap_or_else(|| default.to_vec())
}

/// Mean per-cell σ and (r̄_cur, r̄_EMA) over the cells with samples of a saved state.
fn saved_state(path: &str) {
    let state = CacheState::load(std::path::Path::new(path)).unwrap_or_else(|e| panic!("{e}"));
    let cfg = state.config.reliability.clone();
    let cells: Vec<&[f32]> = state
        .reliability
        .chunks_exact(MOMENTS_PER_CELL)
        .filter(|c| c.iter().any(|&v| v != 0.0))
        .collect();
    println!(
        "{path}: {} steps, {} grid updates, {} of {} cells hold samples",
        state.counters.step,
        state.counters.grid_updates,
        cells.len(),
        reliability::cell_count(&cfg)
    );
    for epsilon in [cfg.epsilon, 1e-8] {
        let c = ReliabilityConfig { epsilon, ..cfg.clone() };
        let (mut s, mut rc, mut re) = (0.0f64, 0.0f64, 0.0f64);
        for m in &cells {
            s += f64::from(reliability::high_lr_weight(&c, PredictorMode::Blend, u32::MAX, m));
            let (a, b) = reliability::reliabilities(&c, m);
            rc += f64::from(a);
            re += f64::from(b);
        }
        let n = cells.len() as f64;
        println!("ε {epsilon:e}: σ {:.4}, r̄ (cur, EMA) ({:.4}, {:.4})", s / n, rc / n, re / n);
    }
    let median = |f: &dyn Fn(&[f32]) -> f32| {
        let mut v: Vec<f32> = cells.iter().map(|m| f(m)).collect();
        v.sort_by(f32::total_cmp);
        v[v.len() / 2]
    };
    println!(
        "median cell: M^y {:.4}, s^y {:.5}, s^f_EMA {:.5} (red)",
        median(&|m| m[0]),
        median(&|m| (m[3] - m[0] * m[0]).max(0.0)),
        median(&|m| (m[18] - m[15] * m[15]).max(0.0))
    );
}

fn main() {
    let mut args = std::env::args().skip(1).peekable();
    if args.peek().is_some_and(|a| a == "--state") {
        args.next();
        return saved_state(&args.next().expect("--state FILE"));
    }
    let steps: Vec<usize> = list(args.next(), &[160, 320, 640, 1280]);
    let seeds: Vec<u64> = list(args.next(), &[2024, 2025, 2026]);
    let noise: f32 = args.next().map_or(0.3, |a| a.parse().expect("a number"));
    let base = config().reliability;
    let variants: Vec<(&str, ReliabilityConfig)> = vec![
        ("paper (per sample, λ 0.9, ε 1e-4)", base.clone()),
        ("batch mean", ReliabilityConfig { update: MomentUpdate::BatchMean, ..base.clone() }),
        ("ε 1e-8", ReliabilityConfig { epsilon: 1e-8, ..base.clone() }),
        ("λ 0.99", ReliabilityConfig { lambda: 0.99, ..base.clone() }),
    ];
    let cells = reliability::cell_count(&base) as usize * MOMENTS_PER_CELL;
    println!("noise ±{noise}; σ (r̄_cur, r̄_EMA) per variant, mean over 500 queries");
    for &seed in &seeds {
        let mut cache = CpuCache::new(CacheState::initial(&config(), bounds()).unwrap());
        let mut moments = vec![vec![0.0f32; cells]; variants.len()];
        let mut rng = Rng(seed);
        let last = *steps.iter().max().unwrap();
        for step in 1..=last {
            let recs = records(&mut rng, 256, noise);
            let samples: Vec<ReliabilitySample> = recs
                .iter()
                .map(|r| {
                    let q = r.query();
                    let (fc, fe) = (cache.predict(&q, false), cache.predict(&q, true));
                    ReliabilitySample {
                        position: r.position,
                        target_rgb: r.target_rgb,
                        f_cur: [fc[0], fc[1], fc[2], 0.0],
                        f_ema: [fe[0], fe[1], fe[2], 0.0],
                    }
                })
                .collect();
            assert!(cache.train_step(&recs).committed);
            for ((_, cfg), m) in variants.iter().zip(&mut moments) {
                assert!(reliability::update(cfg, &bounds(), m, &samples));
            }
            if !steps.contains(&step) {
                continue;
            }
            let mut qrng = Rng(seed ^ 0x51);
            let queries: Vec<CacheQuery> =
                records(&mut qrng, 500, 0.0).iter().map(|r| r.query()).collect();
            let mut line = format!("seed {seed} step {step:5}:");
            for ((name, cfg), m) in variants.iter().zip(&moments) {
                let (mut s, mut rc, mut re) = (0.0f32, 0.0f32, 0.0f32);
                for q in &queries {
                    let p = [q.position[0], q.position[1], q.position[2]];
                    let cell = reliability::cell_index(cfg, &bounds(), p) as usize;
                    let cm = &m[cell * MOMENTS_PER_CELL..(cell + 1) * MOMENTS_PER_CELL];
                    s += reliability::high_lr_weight(cfg, PredictorMode::Blend, step as u32, cm);
                    let (a, b) = reliability::reliabilities(cfg, cm);
                    rc += a;
                    re += b;
                }
                let n = queries.len() as f32;
                line += &format!("  {name}: {:.3} ({:.3}, {:.3})", s / n, rc / n, re / n);
            }
            println!("{line}");
        }
    }
}
