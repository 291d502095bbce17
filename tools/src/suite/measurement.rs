//! What a suite keeps of a case's runs: per seed, per method, each metric's per-frame values,
//! plus the case's frame count and event frames. Baselines store the same, so that a gate
//! reads the baseline and the new runs through one code path, and gates can change without
//! blessing again.

use std::collections::BTreeMap;

use serde::{Deserialize, Serialize};

use super::metric::Metric;
use super::window::Window;
use frame::frame_record::FrameRecord;

#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct SeedRun {
    pub seed: u64,
    /// method label -> metric name -> value per recorded frame (`None`: not measured).
    pub methods: BTreeMap<String, BTreeMap<String, Vec<Option<f64>>>>,
    /// method label -> frames `first..end` -> JOD of those frames (Metric::Cvvdp); kept for
    /// the windows of the suite's JOD gates when blessed, computed from `folder` otherwise.
    #[serde(default, skip_serializing_if = "BTreeMap::is_empty")]
    pub jod: BTreeMap<String, BTreeMap<String, f64>>,
    /// The run folder these came from (absent in a baseline).
    #[serde(skip)]
    pub folder: Option<std::path::PathBuf>,
}

impl SeedRun {
    pub fn from_records(seed: u64, records: &[FrameRecord]) -> SeedRun {
        let mut methods: BTreeMap<String, BTreeMap<String, Vec<Option<f64>>>> = BTreeMap::new();
        let mut rows: Vec<&FrameRecord> = records.iter().collect();
        rows.sort_by_key(|r| (r.method.clone(), r.frame));
        for r in rows {
            let metrics = methods.entry(r.method.clone()).or_default();
            for m in Metric::all().into_iter().filter(|m| m.per_frame()) {
                let series = metrics.entry(m.name().to_string()).or_default();
                series.resize(r.frame as usize, None);
                series.push(m.of(r));
            }
        }
        SeedRun { seed, methods, jod: BTreeMap::new(), folder: None }
    }

    /// JOD of `method` over `range`: kept, or computed from the run folder.
    pub fn jod(&self, method: &str, range: &std::ops::Range<u32>) -> Option<f64> {
        let key = format!("{}..{}", range.start, range.end);
        if let Some(v) = self.jod.get(method).and_then(|j| j.get(&key)) {
            return Some(*v);
        }
        let folder = self.folder.as_ref()?;
        report::jod::of_frames(folder, method, range.start, range.end.checked_sub(1)?)
            .ok()
            .flatten()
    }

    /// Computes and keeps JOD of `method` over `range` (a baseline holds no run folder).
    pub fn keep_jod(&mut self, method: &str, range: &std::ops::Range<u32>) {
        if let Some(v) = self.jod(method, range) {
            let key = format!("{}..{}", range.start, range.end);
            self.jod.entry(method.to_string()).or_default().insert(key, v);
        }
    }

    /// The mean of `metric` over the window's frames; `None` when no frame of it has a value.
    pub fn window_mean(
        &self,
        method: &str,
        metric: Metric,
        range: std::ops::Range<u32>,
    ) -> Option<f64> {
        self.window_mean_of(method, metric, metric.name(), range)
    }

    /// `window_mean` of the series kept under `key` (a metric with parameters, such as
    /// `PassMs`'s passes, keeps one series per parameter set).
    pub fn window_mean_of(
        &self,
        method: &str,
        metric: Metric,
        key: &str,
        range: std::ops::Range<u32>,
    ) -> Option<f64> {
        if !metric.per_frame() {
            return self.jod(method, &range);
        }
        let series = self.methods.get(method)?.get(key)?;
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
        self.per_seed_of(method, metric, metric.name(), window)
    }

    /// `per_seed` of the series kept under `key` (`window_mean_of`).
    pub fn per_seed_of(
        &self,
        method: &str,
        metric: Metric,
        key: &str,
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
                s.window_mean_of(method, metric, key, range.clone())
                    .ok_or_else(|| format!("seed {}: no {key} values for {method} in frames {range:?} (no reference frames there, or the method is not in the run)", s.seed))
            })
            .collect()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// JOD is read per window (kept at bless time), not averaged over frames; a window without
    /// it is an error naming the metric, and higher is better.
    #[test]
    fn jod_is_one_number_per_window() {
        let mut seed = SeedRun::from_records(1, &[]);
        seed.jod.insert("pt".into(), BTreeMap::from([("0..8".to_string(), 7.5)]));
        let runs = CaseRuns { frames: 8, events: vec![4], seeds: vec![seed] };
        assert_eq!(runs.per_seed("pt", Metric::Cvvdp, &Window::Overall), Ok(vec![7.5]));
        let e = runs.per_seed("pt", Metric::Cvvdp, &Window::Before { event: 0 }).unwrap_err();
        assert!(e.contains("no jod values for pt in frames 0..4"), "{e}");
        assert!(Metric::Cvvdp.higher_is_better() && !Metric::Cvvdp.per_frame());
        let json = serde_json::to_value(&runs.seeds[0]).unwrap();
        assert_eq!(json["jod"]["pt"]["0..8"], 7.5);
    }
}
