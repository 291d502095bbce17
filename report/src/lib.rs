//! Records of a run folder: `summary.json`, charts and `report.html`.
//!
//! Reads what the playback wrote (`manifest.json`, `frames.csv`, `frames/<method>/NNNN.{exr,png}`,
//! `reference/NNNN.{exr,png}`) and writes `summary.json`, `charts/*.{svg,png}` and `report.html`.

pub mod base64;
pub mod charts;
pub mod compare;
pub mod html;
pub mod images;
pub mod run;
pub mod summary;
pub mod table;
pub mod viewer;

use std::path::{Path, PathBuf};

pub use html::write_report;
pub use summary::{DEFAULT_WINDOW, write_summary, write_summary_with_window};

/// `flicker report RUN_DIR` or `flicker report --compare RUN_A RUN_B [--out FILE]`.
#[derive(Clone, Debug, clap::Args)]
pub struct ReportArgs {
    /// The run folder (contains manifest.json and frames.csv).
    #[arg(required_unless_present = "compare")]
    pub run_dir: Option<PathBuf>,
    /// Two runs (say before and after a change) in one viewer, with a table of their differences.
    #[arg(long, num_args = 2, value_names = ["RUN_A", "RUN_B"], conflicts_with = "run_dir")]
    pub compare: Option<Vec<PathBuf>>,
    /// Where the comparison page goes [default: RUN_B/compare.html].
    #[arg(long)]
    pub out: Option<PathBuf>,
}

/// Rebuilds summary.json, the charts and report.html of a run folder, or writes the comparison
/// of two runs; returns the page's path.
pub fn report(args: &ReportArgs) -> anyhow::Result<PathBuf> {
    match (&args.compare, &args.run_dir) {
        (Some(runs), _) => {
            let out = args.out.clone().unwrap_or_else(|| runs[1].join("compare.html"));
            compare::write_comparison(&runs[0], &runs[1], &out)
        }
        (None, Some(_)) if args.out.is_some() => anyhow::bail!(
            "--out names the page of --compare; a run's report is RUN_DIR/report.html"
        ),
        (None, Some(run_dir)) => rebuild(run_dir),
        (None, None) => anyhow::bail!("give a run folder, or --compare RUN_A RUN_B"),
    }
}

/// Writes summary.json then report.html (which writes the charts).
pub fn rebuild(run_dir: &Path) -> anyhow::Result<PathBuf> {
    write_summary(run_dir)?;
    write_report(run_dir)
}

#[cfg(test)]
mod tests {
    use clap::Parser;

    #[derive(Parser)]
    struct Cli {
        #[command(flatten)]
        args: super::ReportArgs,
    }

    #[test]
    fn report_takes_a_run_or_two_runs_to_compare() {
        let one = Cli::try_parse_from(["report", "runs/a"]).unwrap().args;
        assert_eq!(one.run_dir.unwrap().to_str(), Some("runs/a"));
        let two =
            Cli::try_parse_from(["report", "--compare", "runs/a", "runs/b", "--out", "c.html"])
                .unwrap()
                .args;
        assert_eq!(two.compare.unwrap().len(), 2);
        assert!(two.run_dir.is_none() && two.out.is_some());
        assert!(Cli::try_parse_from(["report"]).is_err(), "a run is required");
        assert!(
            Cli::try_parse_from(["report", "--compare", "runs/a"]).is_err(),
            "--compare takes two runs"
        );
        let stray_out = Cli::try_parse_from(["report", "runs/a", "--out", "c.html"]).unwrap().args;
        assert!(format!("{:#}", super::report(&stray_out).unwrap_err()).contains("--out"));
    }
}
