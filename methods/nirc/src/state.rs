//! The whole state of a cache (weights, EMA weights, Adam moments, counters, reliability grid),
//! the same for the CPU reference and the GPU, and its file format for warm starts.
//!
//! File: b"FLKNIRC1", u64 length of a JSON header {config, bounds, counters}, the JSON, then the
//! arrays params, ema, adam_m, adam_v, reliability, each as u64 count + little-endian f32s; with
//! sparse grid updates (`optimizer.sparse_grid`) then grid_steps as u64 count + little-endian u32s.

use crate::bounds::SceneBounds;
use crate::config::NircCacheSettings;
use crate::cpu::optimizer::Counters;
use crate::error::NircError;
use crate::layout::ParameterLayout;
use crate::reliability::{MOMENTS_PER_CELL, cell_count};
use serde::{Deserialize, Serialize};
use std::io::{Read, Write};
use std::path::Path;

const MAGIC: &[u8; 8] = b"FLKNIRC1";

#[derive(Clone, Debug, PartialEq)]
pub struct CacheState {
    pub config: NircCacheSettings,
    pub bounds: SceneBounds,
    /// High-LR weights W_t (the trained predictor), layout in `ParameterLayout`.
    pub params: Vec<f32>,
    /// Debiased EMA weights W̄_t.
    pub ema: Vec<f32>,
    pub adam_m: Vec<f32>,
    pub adam_v: Vec<f32>,
    pub counters: Counters,
    /// cells x `MOMENTS_PER_CELL`.
    pub reliability: Vec<f32>,
    /// With sparse grid updates, each grid parameter's own Adam step count (index i is parameter
    /// `layout.mlp_params + i`); empty without them.
    pub grid_steps: Vec<u32>,
}

#[derive(Serialize, Deserialize)]
struct Header {
    config: NircCacheSettings,
    bounds: SceneBounds,
    counters: Counters,
}

/// splitmix64: small, seedable, the same everywhere.
struct SplitMix(u64);
impl SplitMix {
    fn next_f32(&mut self) -> f32 {
        self.0 = self.0.wrapping_add(0x9E37_79B9_7F4A_7C15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
        z ^= z >> 31;
        (z >> 40) as f32 / (1u64 << 24) as f32
    }
    fn symmetric(&mut self, scale: f32) -> f32 {
        (2.0 * self.next_f32() - 1.0) * scale
    }
}

impl CacheState {
    /// Fresh state: MLP weights Xavier-uniform, hash-table entries uniform in ±init_scale, both
    /// from `config.seed`; EMA = weights; Adam moments and grid zero.
    pub fn initial(config: &NircCacheSettings, bounds: SceneBounds) -> Result<Self, NircError> {
        config.validate()?;
        let layout = ParameterLayout::new(config);
        let mut rng = SplitMix(config.seed);
        let mut params = Vec::with_capacity(layout.total_params as usize);
        for m in &layout.matrices {
            let scale = (6.0 / (m.rows + m.cols) as f32).sqrt();
            params.extend((0..m.rows * m.cols).map(|_| rng.symmetric(scale)));
        }
        params.resize(layout.mlp_params as usize, 0.0);
        params.extend(
            (0..layout.grid_table_params()).map(|_| rng.symmetric(config.encoding.init_scale)),
        );
        params.resize(layout.total_params as usize, 0.0);
        let n = params.len();
        Ok(Self {
            config: config.clone(),
            bounds,
            ema: params.clone(),
            params,
            adam_m: vec![0.0; n],
            adam_v: vec![0.0; n],
            counters: Counters::default(),
            reliability: vec![0.0; cell_count(&config.reliability) as usize * MOMENTS_PER_CELL],
            grid_steps: vec![0; Self::grid_steps_len(config, &layout)],
        })
    }

    /// Length of `grid_steps`: the grid's parameters with sparse updates, else 0.
    pub fn grid_steps_len(config: &NircCacheSettings, layout: &ParameterLayout) -> usize {
        if config.optimizer.sparse_grid { layout.grid_params() as usize } else { 0 }
    }

    pub fn layout(&self) -> ParameterLayout {
        ParameterLayout::new(&self.config)
    }

    pub fn save(&self, path: &Path) -> Result<(), NircError> {
        let io = |source| NircError::Io { path: path.to_path_buf(), source };
        let header = serde_json::to_vec(&Header {
            config: self.config.clone(),
            bounds: self.bounds,
            counters: self.counters,
        })
        .map_err(|e| NircError::Format { path: path.to_path_buf(), what: e.to_string() })?;
        let mut bytes = Vec::new();
        bytes.extend_from_slice(MAGIC);
        bytes.extend_from_slice(&(header.len() as u64).to_le_bytes());
        bytes.extend_from_slice(&header);
        for array in [&self.params, &self.ema, &self.adam_m, &self.adam_v, &self.reliability] {
            bytes.extend_from_slice(&(array.len() as u64).to_le_bytes());
            for v in array.iter() {
                bytes.extend_from_slice(&v.to_le_bytes());
            }
        }
        if self.config.optimizer.sparse_grid {
            bytes.extend_from_slice(&(self.grid_steps.len() as u64).to_le_bytes());
            for t in &self.grid_steps {
                bytes.extend_from_slice(&t.to_le_bytes());
            }
        }
        // Write then rename, so a crash never leaves half a state under the final name.
        let tmp = path.with_extension("tmp-nirc");
        let mut f = std::fs::File::create(&tmp).map_err(io)?;
        f.write_all(&bytes).map_err(io)?;
        f.sync_all().map_err(io)?;
        std::fs::rename(&tmp, path).map_err(io)
    }

    pub fn load(path: &Path) -> Result<Self, NircError> {
        let bad = |what: String| NircError::Format { path: path.to_path_buf(), what };
        let mut bytes = Vec::new();
        std::fs::File::open(path)
            .and_then(|mut f| f.read_to_end(&mut bytes))
            .map_err(|source| NircError::Io { path: path.to_path_buf(), source })?;
        let mut at = 0usize;
        let mut take = |n: usize, what: &str| -> Result<&[u8], NircError> {
            let s = bytes
                .get(at..at + n)
                .ok_or_else(|| bad(format!("truncated while reading {what} at byte {at}")))?;
            at += n;
            Ok(s)
        };
        if take(8, "magic")? != MAGIC {
            return Err(bad("does not start with FLKNIRC1 (not a flicker NIRC state)".into()));
        }
        let header_len = u64::from_le_bytes(take(8, "header length")?.try_into().unwrap()) as usize;
        let header: Header = serde_json::from_slice(take(header_len, "JSON header")?)
            .map_err(|e| bad(format!("JSON header: {e}")))?;
        header.config.validate().map_err(|e| bad(e.to_string()))?;
        let layout = ParameterLayout::new(&header.config);
        let cells = cell_count(&header.config.reliability) as usize * MOMENTS_PER_CELL;
        let mut arrays = Vec::new();
        for (name, expected) in [
            ("params", layout.total_params as usize),
            ("ema", layout.total_params as usize),
            ("adam_m", layout.total_params as usize),
            ("adam_v", layout.total_params as usize),
            ("reliability", cells),
        ] {
            let n = u64::from_le_bytes(take(8, name)?.try_into().unwrap()) as usize;
            if n != expected {
                return Err(bad(format!("{name} has {n} values, the config needs {expected}")));
            }
            let raw = take(n * 4, name)?;
            arrays.push(
                raw.chunks_exact(4)
                    .map(|c| f32::from_le_bytes(c.try_into().unwrap()))
                    .collect::<Vec<f32>>(),
            );
        }
        let mut grid_steps = Vec::new();
        if header.config.optimizer.sparse_grid {
            let expected = Self::grid_steps_len(&header.config, &layout);
            let n = u64::from_le_bytes(take(8, "grid_steps")?.try_into().unwrap()) as usize;
            if n != expected {
                return Err(bad(format!("grid_steps has {n} values, the config needs {expected}")));
            }
            grid_steps = take(n * 4, "grid_steps")?
                .chunks_exact(4)
                .map(|c| u32::from_le_bytes(c.try_into().unwrap()))
                .collect();
        }
        if at != bytes.len() {
            return Err(bad(format!("{} trailing bytes", bytes.len() - at)));
        }
        let reliability = arrays.pop().unwrap();
        let adam_v = arrays.pop().unwrap();
        let adam_m = arrays.pop().unwrap();
        let ema = arrays.pop().unwrap();
        let params = arrays.pop().unwrap();
        Ok(Self {
            config: header.config,
            bounds: header.bounds,
            params,
            ema,
            adam_m,
            adam_v,
            counters: header.counters,
            reliability,
            grid_steps,
        })
    }
}
