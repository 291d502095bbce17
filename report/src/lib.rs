//! Records of a run folder: `summary.json`, charts and `report.html`.
//!
//! Reads what the playback wrote (`manifest.json`, `frames.csv`, `frames/<method>/NNNN.{exr,png}`,
//! `reference/NNNN.{exr,png}`) and writes `summary.json`, `charts/*.{svg,png}` and `report.html`.

pub mod base64;
pub mod charts;
pub mod html;
pub mod images;
pub mod run;
pub mod summary;
pub mod table;
pub mod viewer;

use std::path::{Path, PathBuf};

pub use html::write_report;
pub use summary::{DEFAULT_WINDOW, write_summary, write_summary_with_window};

/// `flicker report RUN_DIR`.
#[derive(Clone, Debug, clap::Args)]
pub struct ReportArgs {
    /// The run folder (contains manifest.json and frames.csv).
    pub run_dir: PathBuf,
}

/// Rebuilds summary.json, the charts and report.html of a run folder; returns the report's path.
pub fn report(args: &ReportArgs) -> anyhow::Result<PathBuf> {
    rebuild(&args.run_dir)
}

/// Writes summary.json then report.html (which writes the charts).
pub fn rebuild(run_dir: &Path) -> anyhow::Result<PathBuf> {
    write_summary(run_dir)?;
    write_report(run_dir)
}
