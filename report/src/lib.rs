//! Records of a run folder: `summary.json`, charts and `report.html`.
//!
//! Reads what the playback wrote (`manifest.json`, `frames.csv`, `frames/<method>/NNNN.{exr,png}`,
//! `reference/NNNN.{exr,png}`) and writes `summary.json`, `charts/*.{svg,png}` and `report.html`.

pub mod charts;
pub mod compare;
pub mod data_uri;
pub mod declared;
pub mod html;
pub mod images;
pub mod jod;
pub mod page;
pub mod run;
pub mod summary;
pub mod table;
pub mod viewer;
pub mod window;

use std::path::{Path, PathBuf};

use declared::MethodChart;

pub use html::write_report;
pub use summary::{write_summary, write_summary_with_window};
pub use window::DEFAULT_WINDOW;

/// What [`report`] writes: a run's report (`run_dir`), or the comparison of two runs
/// (`compare`, the page at `out`, by default RUN_B/compare.html); `charts`: the registered
/// methods' charts, drawn where the run has their columns.
#[derive(Clone, Debug, Default)]
pub struct ReportOptions {
    pub run_dir: Option<PathBuf>,
    pub compare: Option<Vec<PathBuf>>,
    pub out: Option<PathBuf>,
    pub charts: Vec<MethodChart>,
}

/// Rebuilds summary.json, the charts and report.html of a run folder, or writes the comparison
/// of two runs; returns the page's path.
pub fn report(args: &ReportOptions) -> anyhow::Result<PathBuf> {
    match (&args.compare, &args.run_dir) {
        (Some(runs), _) => {
            let out = args.out.clone().unwrap_or_else(|| runs[1].join("compare.html"));
            compare::write_comparison(&runs[0], &runs[1], &out)
        }
        (None, Some(_)) if args.out.is_some() => anyhow::bail!(
            "--out names the page of --compare; a run's report is RUN_DIR/report.html"
        ),
        (None, Some(run_dir)) => rebuild(run_dir, &args.charts),
        (None, None) => anyhow::bail!("give a run folder, or --compare RUN_A RUN_B"),
    }
}

/// Writes summary.json then report.html (which writes the charts, `charts` among them where the
/// run has their columns).
pub fn rebuild(run_dir: &Path, charts: &[MethodChart]) -> anyhow::Result<PathBuf> {
    write_summary(run_dir)?;
    write_report(run_dir, charts)
}

#[cfg(test)]
mod tests {
    use super::{ReportOptions, report};

    #[test]
    fn out_belongs_to_a_comparison() {
        let stray_out = ReportOptions {
            run_dir: Some("runs/a".into()),
            compare: None,
            out: Some("c.html".into()),
            charts: vec![],
        };
        assert!(format!("{:#}", report(&stray_out).unwrap_err()).contains("--out"));
    }
}
