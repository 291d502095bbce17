//! `flicker report`'s command line, read into [`report::ReportOptions`].

use std::path::PathBuf;

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

impl ReportArgs {
    pub fn options(self) -> report::ReportOptions {
        report::ReportOptions {
            run_dir: self.run_dir,
            compare: self.compare,
            out: self.out,
            charts: playback::methods::registry::charts(),
        }
    }
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
        assert!(
            format!("{:#}", report::report(&stray_out.options()).unwrap_err()).contains("--out")
        );
    }
}
