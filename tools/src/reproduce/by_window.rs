//! A case's statistics over several windows, one table per metric with a column per window
//! (a dynamic scene's frames before, during and after its events): `by_window: (metrics:
//! [Flip, CacheMean], windows: [Around(event: 0, from: -4, to: 0), After(event: 0, frames: 4)])`.
//! A case with `by_window` is played even where no claim needs it.

use serde::Deserialize;

use super::case_methods::CaseMethods;
use super::table::{CaseTable, cell};
use crate::suite::measurement::CaseRuns;
use playback::methods::FolderInput;

use crate::suite::metric::Metric;
use crate::suite::window::Window;

#[derive(Clone, Debug, PartialEq, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ByWindow {
    pub metrics: Vec<Metric>,
    pub windows: Vec<Window>,
}

impl ByWindow {
    /// Each metric once, read from frames.csv without parameters, and recorded by at least one
    /// of the case's methods; at least one window.
    pub fn check(&self, case: &CaseMethods) -> Result<(), String> {
        if self.metrics.is_empty() || self.windows.is_empty() {
            return Err("by_window: expected at least one metric and one window".into());
        }
        for (i, m) in self.metrics.iter().enumerate() {
            let name = m.name();
            if self.metrics[..i].contains(m) {
                return Err(format!("by_window: {name} is listed twice"));
            }
            if m.from_images()
                || *m == Metric::PassMs
                || m.from_images_by().is_some_and(|i| i.input == FolderInput::WholeRun)
                || !m.per_frame()
            {
                return Err(format!(
                    "by_window: {name} needs a claim's parameters or is not a per-frame number; expected a per-frame metric such as Flip or CacheMean"
                ));
            }
            if case.computed.is_some() {
                return Err("by_window on a computed case, which has no frames".into());
            }
            if !case.kinds.values().any(|kind| m.recorded_by(kind, case.references)) {
                return Err(format!(
                    "by_window: no method of the case records {name}{}",
                    if case.references { "" } else { " (the scenario has no reference frames)" }
                ));
            }
        }
        Ok(())
    }

    /// One table per metric: every method of the case, a column per window.
    pub fn tables(&self, case: &str, runs: &CaseRuns) -> Vec<CaseTable> {
        self.metrics
            .iter()
            .map(|&metric| CaseTable {
                case: format!("{case}, {}", metric.name()),
                seeds: runs.seeds.len(),
                columns: self.windows.iter().map(Window::name).collect(),
                rows: runs
                    .methods()
                    .into_iter()
                    .map(|m| {
                        let cells = self
                            .windows
                            .iter()
                            .map(|w| cell(runs.per_seed_of(&m, metric, metric.name(), w)))
                            .collect();
                        (m, cells)
                    })
                    .collect(),
            })
            .collect()
    }
}

#[cfg(test)]
mod tests {
    use std::collections::BTreeMap;

    use super::*;
    use crate::suite::measurement::SeedRun;

    fn seed(seed: u64, values: &[f64]) -> SeedRun {
        let series = values.iter().map(|&v| Some(v)).collect();
        let metrics = BTreeMap::from([("cache_mean".to_string(), series)]);
        let methods = BTreeMap::from([("vb".to_string(), metrics)]);
        SeedRun { seed, methods, jod: BTreeMap::new(), folder: None }
    }

    /// Each window's cell is the mean over seeds of that window's frames, with its interval.
    #[test]
    fn a_column_per_window_a_table_per_metric() {
        let runs = CaseRuns {
            frames: 6,
            events: vec![2],
            seeds: vec![
                seed(1, &[1.0, 1.0, 4.0, 4.0, 2.0, 2.0]),
                seed(2, &[1.0, 1.0, 4.0, 4.0, 2.0, 2.0]),
            ],
        };
        let by = ByWindow {
            metrics: vec![Metric::shipped("CacheMean")],
            windows: vec![
                Window::Around { event: 0, from: -2, to: 0 },
                Window::After { event: 0, frames: 2 },
                Window::Around { event: 0, from: 2, to: 4 },
            ],
        };
        let t = by.tables("flash", &runs);
        assert_eq!(t.len(), 1);
        assert_eq!(t[0].case, "flash, cache_mean");
        assert_eq!(t[0].columns, ["event_0-2..+0", "after_event_0(2)", "event_0+2..+4"]);
        assert_eq!(
            t[0].rows,
            [(
                "vb".to_string(),
                vec![
                    "1.0000 [1.0000, 1.0000]".to_string(),
                    "4.0000 [4.0000, 4.0000]".to_string(),
                    "2.0000 [2.0000, 2.0000]".to_string()
                ]
            )]
        );
    }
}
