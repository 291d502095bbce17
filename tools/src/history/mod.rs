//! The results history: every `flicker reproduce`, `suite` and `bench` run appends its values,
//! intervals and verdicts (`record`: one JSON file per run, safe for concurrent writers and
//! kept in git), and `flicker history` shows each claim, gate or ratio across commits
//! (`series`: a table and a chart per series), flagging a changed verdict and a drift beyond
//! the margin (`sources::claim_margin`) while the verdict holds.

pub mod record;
pub mod series;
pub mod sources;

use std::path::{Path, PathBuf};

use anyhow::Result;

pub use record::{DEFAULT_DIR, Entry, Kind, Record, append, read};
pub use series::{Flag, Series, series};

use crate::reproduce::ReproduceOutcome;
use crate::reproduce::run::load_claims;
use crate::suite::SuiteOutcome;

/// A reproduce run's record: one entry per claim of every paper played.
pub fn reproduce_record(
    outcome: &ReproduceOutcome,
    claims_dir: &Path,
    paper: &str,
    scale: &str,
) -> Result<Record> {
    let adapter = sources::adapter_of_runs(&outcome.folder, "none (computed on the CPU)");
    let mut r = Record::now(Kind::Reproduce, paper, scale, &adapter, claims_dir);
    let all = load_claims(claims_dir, paper)?;
    for o in &outcome.claims {
        let claim = all
            .iter()
            .filter(|c| c.paper == o.paper)
            .flat_map(|c| c.claims.iter())
            .find(|c| c.id == o.id);
        if let Some(c) = claim {
            r.entries.push(sources::claim_entry(&o.paper, c, &o.judged));
        }
    }
    Ok(r)
}

/// A suite run's record: one entry per judged gate.
pub fn suite_record(outcome: &SuiteOutcome, suite_file: &Path) -> Result<Record> {
    let suite = crate::suite::Suite::load(suite_file)?;
    let adapter = sources::adapter_of_runs(&outcome.folder, "frames from disk / cpu");
    let mut r = Record::now(Kind::Suite, &suite.name, "-", &adapter, suite_file);
    r.entries = outcome.results.iter().map(sources::gate_entry).collect();
    Ok(r)
}

pub struct ShowOptions {
    pub history: PathBuf,
    /// Where history.md and the charts go.
    pub out: PathBuf,
    /// Only series whose kind, scale or id contains this.
    pub filter: Option<String>,
}

pub struct Shown {
    pub series: Vec<Series>,
    pub markdown: String,
    pub report: PathBuf,
    pub charts: Vec<PathBuf>,
}

impl Shown {
    /// The series whose latest commit is flagged against the one before.
    pub fn flagged_now(&self) -> Vec<&Series> {
        self.series.iter().filter(|s| !s.latest_flags().is_empty()).collect()
    }
}

/// `flicker history`: the series of the history in `opts.history`, written as `OUT/history.md`
/// and one SVG chart per series under `OUT/charts/`.
pub fn show(opts: &ShowOptions) -> Result<Shown> {
    let records: Vec<Record> = read(&opts.history)?.into_iter().map(|(_, r)| r).collect();
    let mut all = series(&records);
    if let Some(f) = &opts.filter {
        all.retain(|s| {
            s.key.id.contains(f.as_str()) || s.key.kind.name() == f || s.key.scale == *f
        });
    }
    let mut md = series::markdown(&all);
    if all.is_empty() {
        md.push_str(&format!("\nNo records in {}.\n", opts.history.display()));
    }
    let report = opts.out.join("history.md");
    frame::output::write_text(&report, &md)?;
    let mut charts = Vec::new();
    for (i, s) in all.iter().enumerate() {
        let name: String = format!("{}_{}_{}", s.key.kind.name(), s.key.scale, s.key.id)
            .chars()
            .map(|c| if c.is_ascii_alphanumeric() || "-_.".contains(c) { c } else { '_' })
            .collect();
        let path = opts.out.join("charts").join(format!("{i:03}_{name}.svg"));
        let (svg, _) = report::charts::plot::to_svg(&series::chart(s))?;
        frame::output::write_text(&path, &svg)?;
        charts.push(path);
    }
    Ok(Shown { series: all, markdown: md, report, charts })
}
