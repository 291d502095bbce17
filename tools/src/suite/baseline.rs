//! Baselines: `suites/baselines/SUITE.json`, one entry per adapter (lavapipe and a GPU give
//! different numbers), each with the commit, the date and the per-seed measurements.

use std::collections::BTreeMap;
use std::path::Path;

use anyhow::{Context, Result};
use serde::{Deserialize, Serialize};

use super::measurement::CaseRuns;

#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Baseline {
    pub commit: String,
    /// UTC, ISO 8601.
    pub date: String,
    /// The adapter as manifest.json states it (`gpu.summary`).
    pub adapter: serde_json::Value,
    pub cases: BTreeMap<String, CaseRuns>,
}

/// The file: adapter key -> baseline.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct BaselineFile {
    pub suite: String,
    pub adapters: BTreeMap<String, Baseline>,
}

impl BaselineFile {
    /// The file's baselines; an empty set when there is no file yet.
    pub fn load(path: &Path) -> Result<BaselineFile> {
        if !path.exists() {
            return Ok(BaselineFile::default());
        }
        let text =
            std::fs::read_to_string(path).with_context(|| format!("reading {}", path.display()))?;
        serde_json::from_str(&text).map_err(|e| {
            anyhow::anyhow!(
                "{}:{}:{}: not a baseline file ({e}); expected the JSON `flicker suite bless` writes",
                path.display(),
                e.line(),
                e.column()
            )
        })
    }

    /// The baseline to compare with on `adapter`: its own (`exact`), else a stand-in blessed on
    /// another adapter: one of the same family first (`adapter_family`: the same driver under
    /// another version, e.g. llvmpipe of another LLVM), then of the same device type, then any.
    /// Ties go to the first key in the file's order. None when the file has no baseline.
    pub fn for_adapter(&self, adapter: &render::gpu::AdapterSummary) -> Option<Chosen<'_>> {
        let key = adapter_key(adapter);
        if let Some((k, b)) = self.adapters.get_key_value(&key) {
            return Some(Chosen { key: k, baseline: b, exact: true });
        }
        let family = adapter_family(&key);
        let rank = |(k, b): &(&String, &Baseline)| {
            if adapter_family(k) == family {
                0
            } else if b.adapter.get("device_type").and_then(|t| t.as_str())
                == Some(adapter.device_type.as_str())
            {
                1
            } else {
                2
            }
        };
        let (k, b) = self.adapters.iter().min_by_key(|e| rank(e))?;
        Some(Chosen { key: k, baseline: b, exact: false })
    }

    pub fn save(&self, path: &Path) -> Result<()> {
        frame::output::write_text(path, &(serde_json::to_string_pretty(self)? + "\n"))
    }
}

/// A baseline chosen for an adapter, and whether it was blessed on that adapter.
#[derive(Clone, Copy, Debug)]
pub struct Chosen<'a> {
    pub key: &'a str,
    pub baseline: &'a Baseline,
    pub exact: bool,
}

/// An adapter key without the versions in parentheses, e.g. `llvmpipe / Vulkan` for
/// `llvmpipe (LLVM 15.0.6, 256 bits) / Vulkan`: the same driver built against another version.
pub fn adapter_family(key: &str) -> String {
    let mut out = String::new();
    let mut depth = 0usize;
    for c in key.chars() {
        match c {
            '(' => depth += 1,
            ')' => depth = depth.saturating_sub(1),
            _ if depth == 0 => out.push(c),
            _ => {}
        }
    }
    out.split_whitespace().collect::<Vec<_>>().join(" ")
}

/// The key a baseline is stored under: the adapter's name and backend.
pub fn adapter_key(adapter: &render::gpu::AdapterSummary) -> String {
    format!("{} / {}", adapter.name, adapter.backend)
}

/// Seconds since the Unix epoch as `YYYY-MM-DDTHH:MM:SSZ` (days to civil date: H. Hinnant's
/// algorithm), so that no date crate is needed.
pub fn utc_timestamp(unix_seconds: u64) -> String {
    let days = (unix_seconds / 86_400) as i64;
    let secs = unix_seconds % 86_400;
    let z = days + 719_468;
    let era = z.div_euclid(146_097);
    let doe = z - era * 146_097;
    let yoe = (doe - doe / 1460 + doe / 36_524 - doe / 146_096) / 365;
    let doy = doe - (365 * yoe + yoe / 4 - yoe / 100);
    let mp = (5 * doy + 2) / 153;
    let day = doy - (153 * mp + 2) / 5 + 1;
    let month = if mp < 10 { mp + 3 } else { mp - 9 };
    let year = yoe + era * 400 + i64::from(month <= 2);
    format!(
        "{year:04}-{month:02}-{day:02}T{:02}:{:02}:{:02}Z",
        secs / 3600,
        secs / 60 % 60,
        secs % 60
    )
}

pub fn now() -> String {
    utc_timestamp(
        std::time::SystemTime::now()
            .duration_since(std::time::UNIX_EPOCH)
            .map(|d| d.as_secs())
            .unwrap_or(0),
    )
}

#[cfg(test)]
mod tests {
    use super::*;

    fn adapter(name: &str, backend: &str, device_type: &str) -> render::gpu::AdapterSummary {
        render::gpu::AdapterSummary {
            name: name.into(),
            backend: backend.into(),
            driver: String::new(),
            driver_info: String::new(),
            device_type: device_type.into(),
        }
    }

    fn file(adapters: &[render::gpu::AdapterSummary]) -> BaselineFile {
        let adapters = adapters
            .iter()
            .map(|a| {
                let b = Baseline {
                    commit: adapter_key(a),
                    date: String::new(),
                    adapter: serde_json::to_value(a).unwrap(),
                    cases: BTreeMap::new(),
                };
                (adapter_key(a), b)
            })
            .collect();
        BaselineFile { suite: "s".into(), adapters }
    }

    #[test]
    fn another_adapter_stands_in_nearest_first() {
        let lvp15 = adapter("llvmpipe (LLVM 15.0.6, 256 bits)", "Vulkan", "Cpu");
        let lvp19 = adapter("llvmpipe (LLVM 19.1.7, 256 bits)", "Vulkan", "Cpu");
        let swift = adapter("SwiftShader Device (Subzero)", "Vulkan", "Cpu");
        let h100 = adapter("NVIDIA H100 80GB HBM3", "Vulkan", "DiscreteGpu");
        let a100 = adapter("NVIDIA A100", "Vulkan", "DiscreteGpu");
        assert_eq!(adapter_family(&adapter_key(&lvp19)), "llvmpipe / Vulkan");
        let chosen = |f: &BaselineFile, a| f.for_adapter(a).map(|c| (c.key.to_string(), c.exact));
        let all = file(&[h100.clone(), lvp15.clone(), swift.clone()]);
        assert_eq!(chosen(&all, &lvp15), Some((adapter_key(&lvp15), true)));
        // The same driver under another LLVM before another CPU driver.
        assert_eq!(chosen(&all, &lvp19), Some((adapter_key(&lvp15), false)));
        // Another GPU: the GPU's baseline before the CPU drivers'.
        assert_eq!(chosen(&all, &a100), Some((adapter_key(&h100), false)));
        // Nothing alike: the first key in the file's order.
        let cpus = file(&[swift.clone(), lvp15.clone()]);
        assert_eq!(chosen(&cpus, &a100), Some((adapter_key(&swift), false)));
        assert_eq!(chosen(&file(&[]), &a100), None);
    }

    #[test]
    fn timestamps_match_date() {
        // `date -u -d @0`, `date -u -d @951782400` (a leap day), `date -u -d @1795737600`.
        assert_eq!(utc_timestamp(0), "1970-01-01T00:00:00Z");
        assert_eq!(utc_timestamp(951_782_400), "2000-02-29T00:00:00Z");
        assert_eq!(utc_timestamp(1_795_737_600 + 3661), "2026-11-27T01:01:01Z");
    }
}
