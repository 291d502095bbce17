//! What a suite keeps of a case's runs: per seed, per method, each metric's per-frame values,
//! plus the case's frame count and event frames. Baselines store the same, so that a gate
//! reads the baseline and the new runs through one code path, and gates can change without
//! blessing again.

use std::collections::BTreeMap;

use serde::{Deserialize, Serialize};

use super::metric::Metric;
use super::window::Window;
use systems::frame_record::FrameRecord;

#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct SeedRun {
    pub seed: u64,
    /// method label -> metric name -> value per recorded frame (`None`: not measured).
    pub methods: BTreeMap<String, BTreeMap<String, Vec<Option<f64>>>>,
}

impl SeedRun {
    pub fn from_records(seed: u64, records: &[FrameRecord]) -> SeedRun {
        let mut methods: BTreeMap<String, BTreeMap<String, Vec<Option<f64>>>> = BTreeMap::new();
        let mut rows: Vec<&FrameRecord> = records.iter().collect();
        rows.sort_by_key(|r| (r.method.clone(), r.frame));
        for r in rows {
            let metrics = methods.entry(r.method.clone()).or_default();
            for m in Metric::ALL {
                let series = metrics.entry(m.name().to_string()).or_default();
                series.resize(r.frame as usize, None);
                series.push(m.of(r));
            }
        }
        SeedRun { seed, methods }
    }

    /// The mean of `metric` over the window's frames; `None` when no frame of it has a value.
    pub fn window_mean(
        &self,
        method: &str,
        metric: Metric,
        range: std::ops::Range<u32>,
    ) -> Option<f64> {
        let series = self.methods.get(method)?.get(metric.name())?;
        let values: Vec<f64> = range
            .filter_map(|f| series.get(f as usize).copied().flatten())
            .filter(|v| v.is_finite())
            .collect();
        (!values.is_empty()).then(|| values.iter().sum::<f64>() / values.len() as f64)
    }
}

/// All seeds of one case.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct CaseRuns {
    pub frames: u32,
    /// Recorded frames of the scenario's events, ascending.
    pub events: Vec<u32>,
    pub seeds: Vec<SeedRun>,
}

impl CaseRuns {
    pub fn methods(&self) -> Vec<String> {
        let mut out: Vec<String> =
            self.seeds.iter().flat_map(|s| s.methods.keys().cloned()).collect();
        out.sort();
        out.dedup();
        out
    }

    /// One value per seed: the window mean of `metric` for `method`; an error says what is missing.
    pub fn per_seed(
        &self,
        method: &str,
        metric: Metric,
        window: &Window,
    ) -> Result<Vec<f64>, String> {
        let range = window.frames(self.frames, &self.events).ok_or_else(|| {
            format!(
                "window {} needs event {:?}, but the case has {} event(s)",
                window.name(),
                window.event(),
                self.events.len()
            )
        })?;
        if range.is_empty() {
            return Err(format!(
                "window {} holds no frames ({range:?} of {} frames)",
                window.name(),
                self.frames
            ));
        }
        self.seeds
            .iter()
            .map(|s| {
                s.window_mean(method, metric, range.clone())
                    .ok_or_else(|| format!("seed {}: no {} values for {method} in frames {range:?} (no reference frames there, or the method is not in the run)", s.seed, metric.name()))
            })
            .collect()
    }
}
