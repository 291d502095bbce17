//! Shared test fixtures: a small cache configuration, a seeded random stream, records of a
//! known smooth function.
#![allow(dead_code)]

use nirc::config::{DirectionEncoding, HashGridSettings, NetworkSettings, ReliabilitySettings};
use nirc::{CacheState, NircCacheSettings, SceneBounds, TrainingRecord};

pub struct Rng(pub u64);
impl Rng {
    pub fn f32(&mut self) -> f32 {
        self.0 = self.0.wrapping_mul(6364136223846793005).wrapping_add(1442695040888963407);
        ((self.0 >> 40) as f32) / (1u64 << 24) as f32
    }
    pub fn range(&mut self, lo: f32, hi: f32) -> f32 {
        lo + (hi - lo) * self.f32()
    }
    pub fn direction(&mut self) -> [f32; 3] {
        loop {
            let v = [self.range(-1.0, 1.0), self.range(-1.0, 1.0), self.range(-1.0, 1.0)];
            let l = (v[0] * v[0] + v[1] * v[1] + v[2] * v[2]).sqrt();
            if l > 0.1 && l <= 1.0 {
                return v.map(|x| x / l);
            }
        }
    }
}

/// Width 16, 2 hidden layers, 4 levels (two dense, two hashed into 2^10 entries).
pub fn small_config() -> NircCacheSettings {
    NircCacheSettings {
        encoding: HashGridSettings {
            levels: 4,
            features_per_level: 2,
            log2_table_size: 10,
            base_resolution: 4,
            growth_factor: 1.5,
            init_scale: 1e-4,
        },
        direction: DirectionEncoding::SphericalHarmonics { bands: 3 },
        network: NetworkSettings { width: 32, hidden_layers: 2 },
        reliability: ReliabilitySettings {
            resolution: 8,
            log2_cells: 8,
            warmup: 2,
            ..Default::default()
        },
        max_batch: 512,
        ..Default::default()
    }
}

pub fn bounds() -> SceneBounds {
    SceneBounds::new([-1.0, -0.5, -2.0], [3.0, 1.5, 2.0])
}

/// The smooth RGB field the regression tests fit.
pub fn field(p: [f32; 3], d: [f32; 3]) -> [f32; 3] {
    [
        1.0 + 0.5 * (1.3 * p[0]).sin() * (0.7 * p[2]).cos(),
        0.6 + 0.3 * p[1] + 0.1 * d[2],
        0.2 + 0.15 * (p[0] + p[2]).cos(),
    ]
}

pub fn records(rng: &mut Rng, n: usize) -> Vec<TrainingRecord> {
    let b = bounds();
    (0..n)
        .map(|_| {
            let p = [
                rng.range(b.min[0], b.max[0]),
                rng.range(b.min[1], b.max[1]),
                rng.range(b.min[2], b.max[2]),
            ];
            let d = rng.direction();
            TrainingRecord::new(p, d, field(p, d))
        })
        .collect()
}

/// A state whose grid entries and weights are far from their tiny initial values, with EMA
/// weights different from the trained ones.
pub fn randomized_state(config: &NircCacheSettings, seed: u64) -> CacheState {
    let mut s = CacheState::initial(config, bounds()).unwrap();
    let mut rng = Rng(seed);
    let mlp = s.layout().mlp_params as usize;
    for (i, w) in s.params.iter_mut().enumerate() {
        if i >= mlp {
            *w = rng.range(-0.5, 0.5);
        }
    }
    for (w, e) in s.params.iter().zip(s.ema.iter_mut()) {
        *e = w + rng.range(-0.05, 0.05);
    }
    s
}
