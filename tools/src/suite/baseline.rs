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

    pub fn save(&self, path: &Path) -> Result<()> {
        systems::output::write_text(path, &(serde_json::to_string_pretty(self)? + "\n"))
    }
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

    #[test]
    fn timestamps_match_date() {
        // `date -u -d @0`, `date -u -d @951782400` (a leap day), `date -u -d @1795737600`.
        assert_eq!(utc_timestamp(0), "1970-01-01T00:00:00Z");
        assert_eq!(utc_timestamp(951_782_400), "2000-02-29T00:00:00Z");
        assert_eq!(utc_timestamp(1_795_737_600 + 3661), "2026-11-27T01:01:01Z");
    }
}
