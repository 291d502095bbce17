//! The results history on disk: one small JSON file per run (`DIR/KIND/SCALE/DATE-COMMIT-NAME-PID-N.json`),
//! each a [`Record`] of one command at one commit and scale. One file per run, never an edited
//! one, so that writers on several machines, processes or threads never meet (each name is
//! unique, each file written whole through a temporary file and a rename), and a history kept
//! in git merges without conflicts.

use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicUsize, Ordering};

use anyhow::{Context, Result, bail};
use serde::{Deserialize, Serialize};

/// The format's version; a reader refuses a newer one.
pub const FORMAT: u32 = 1;

/// The default history folder, relative to where `flicker` runs.
pub const DEFAULT_DIR: &str = "results/history";

/// Which command wrote a record.
#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord, Hash, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum Kind {
    Reproduce,
    Suite,
    Bench,
}

impl Kind {
    pub fn name(self) -> &'static str {
        match self {
            Kind::Reproduce => "reproduce",
            Kind::Suite => "suite",
            Kind::Bench => "bench",
        }
    }
}

/// One run of `flicker reproduce`, `suite` or `bench` at one commit and scale.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Record {
    pub version: u32,
    pub kind: Kind,
    /// The paper (or `all`), the suite's name, or the bench's form (`speed`, `metrics`).
    pub name: String,
    /// `smoke`, `lab` or `paper` for reproduce; `-` where a command has no scale.
    pub scale: String,
    /// The checkout's commit (`unknown` outside git), without `-dirty`.
    pub commit: String,
    /// The checkout had local changes: the numbers belong to no commit exactly.
    pub dirty: bool,
    /// `debug` or `release`: the build that measured.
    pub profile: String,
    /// The adapter the runs played on (name / backend), or what measured instead.
    pub adapter: String,
    /// UTC, `YYYY-MM-DDTHH:MM:SSZ`.
    pub date: String,
    /// The command line, for a reader who wants to rerun it.
    pub command: String,
    pub entries: Vec<Entry>,
}

/// One claim, gate or ratio of a record.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Entry {
    /// `PAPER/CLAIM`, `CASE/METHOD/GATE` or the bench ratio's name.
    pub id: String,
    /// The measured value (for a relation, the mean paired difference); `None`: not measured.
    pub value: Option<f64>,
    /// Its interval (95% unless the claim says otherwise), where there is one.
    pub lo: Option<f64>,
    pub hi: Option<f64>,
    /// The verdict's name as the command wrote it (`reproduced`, `pass`, ...); none for ratios.
    pub verdict: Option<String>,
    /// The smallest change of `value` that matters (a drift beyond it is flagged).
    pub margin: Option<f64>,
    /// Where `margin` comes from.
    #[serde(default)]
    pub margin_from: String,
    /// What the command printed for it (means, bounds, seeds).
    #[serde(default)]
    pub detail: String,
}

impl Record {
    /// A record of this checkout now: commit and dirty flag from git in `dir`'s checkout, the
    /// build profile of this program, the current UTC time.
    pub fn now(kind: Kind, name: &str, scale: &str, adapter: &str, dir: &Path) -> Record {
        let full = playback::manifest::commit(&dir.join("x"));
        let (commit, dirty) = match full.strip_suffix("-dirty") {
            Some(c) => (c.to_string(), true),
            None => (full, false),
        };
        let command = std::env::args()
            .map(|a| if a.contains(' ') { format!("'{a}'") } else { a })
            .collect::<Vec<_>>()
            .join(" ");
        Record {
            version: FORMAT,
            kind,
            name: name.into(),
            scale: scale.into(),
            commit,
            dirty,
            profile: if cfg!(debug_assertions) { "debug" } else { "release" }.into(),
            adapter: adapter.into(),
            date: crate::suite::baseline::now(),
            command,
            entries: Vec::new(),
        }
    }
}

/// Letters, digits, `.`, `_` and `-`; anything else becomes `_` (a name in a file name).
fn file_safe(s: &str) -> String {
    s.chars()
        .map(|c| if c.is_ascii_alphanumeric() || "._-".contains(c) { c } else { '_' })
        .collect()
}

/// Appends `record` to the history in `dir`: a new file, written whole or not at all, whose
/// name no other writer (process, thread or machine) chooses. Returns its path.
pub fn append(dir: &Path, record: &Record) -> Result<PathBuf> {
    static SEQUENCE: AtomicUsize = AtomicUsize::new(0);
    let n = SEQUENCE.fetch_add(1, Ordering::Relaxed);
    let nanos = std::time::SystemTime::now()
        .duration_since(std::time::UNIX_EPOCH)
        .map_or(0, |d| d.subsec_nanos());
    let host = std::env::var("HOSTNAME").unwrap_or_default();
    let commit: String = record.commit.chars().take(12).collect();
    let name = format!(
        "{}-{commit}{}-{}-{}{}-{}-{n}-{nanos}.json",
        record.date.replace(':', ""),
        if record.dirty { "-dirty" } else { "" },
        file_safe(&record.name),
        if host.is_empty() { String::new() } else { format!("{}-", file_safe(&host)) },
        std::process::id(),
        record.profile,
    );
    let path = dir.join(record.kind.name()).join(file_safe(&record.scale)).join(name);
    let text = serde_json::to_string_pretty(record)? + "\n";
    frame::output::write_text(&path, &text)
        .with_context(|| format!("appending to the results history {}", dir.display()))?;
    Ok(path)
}

/// Every record under `dir` (recursively; `*.json` files only, so a writer's temporary file is
/// never read), ordered by date, then file name. A missing folder is an empty history; a file
/// that is not a record is an error naming the file, line and column.
pub fn read(dir: &Path) -> Result<Vec<(PathBuf, Record)>> {
    let mut files = Vec::new();
    if dir.exists() {
        collect(dir, &mut files)?;
    }
    files.sort();
    let mut records = Vec::new();
    for path in files {
        let text = std::fs::read_to_string(&path)
            .with_context(|| format!("reading {}", path.display()))?;
        let record: Record = serde_json::from_str(&text).map_err(|e| {
            anyhow::anyhow!(
                "{}:{}:{}: expected a results-history record (docs/history.md): {e}",
                path.display(),
                e.line(),
                e.column()
            )
        })?;
        if record.version > FORMAT {
            bail!(
                "{}:1: a history record of version {} (this flicker reads up to {FORMAT}); update flicker",
                path.display(),
                record.version
            );
        }
        records.push((path, record));
    }
    records.sort_by(|a, b| (&a.1.date, &a.0).cmp(&(&b.1.date, &b.0)));
    Ok(records)
}

fn collect(dir: &Path, out: &mut Vec<PathBuf>) -> Result<()> {
    let entries = std::fs::read_dir(dir).with_context(|| format!("reading {}", dir.display()))?;
    for e in entries {
        let path = e?.path();
        if path.is_dir() {
            collect(&path, out)?;
        } else if path.extension().is_some_and(|x| x == "json") {
            out.push(path);
        }
    }
    Ok(())
}
