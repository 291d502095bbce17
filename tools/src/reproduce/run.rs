//! Playing what the claims need: each paper's cases over seeds through the suite's
//! `play_cases`, then every claim judged on its case's per-seed window means.

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

use anyhow::{Result, bail};

use super::claims::{Claims, Comparison, Scale};
use super::judge::judge;
use super::report::{self, PaperResult};
use super::table::{CaseTable, cell};
use super::verdict::Judged;
use crate::suite::measurement::CaseRuns;
use playback::methods::FolderInput;

use crate::suite::metric::Metric;
use crate::suite::run::play_cases;
use crate::suite::spec::Case;

pub struct ReproduceOptions {
    /// A paper's stem (`claims/PAPER.ron`) or `all`.
    pub paper: String,
    /// The folder of claims files [default: claims].
    pub claims_dir: PathBuf,
    pub scale: Scale,
    /// Seeds per case [default: each case's own list].
    pub seeds: Option<usize>,
    /// Where runs, reproduce.md and reproduce.html go [default: runs/reproduce_PAPER_SCALE].
    pub out: Option<PathBuf>,
    pub cache_dir: Option<PathBuf>,
    pub progress: bool,
}

pub struct ReproduceOutcome {
    pub folder: PathBuf,
    pub markdown: String,
    /// Every claim of every paper played, in file order.
    pub claims: Vec<ClaimOutcome>,
}

/// One claim's outcome.
#[derive(Clone, Debug, PartialEq)]
pub struct ClaimOutcome {
    pub paper: String,
    pub id: String,
    /// The claims file declares it not comparable (nothing is played for it).
    pub declared_not_comparable: bool,
    /// Its statistic is a measured time (differs run to run).
    pub timing: bool,
    pub judged: Judged,
}

/// The claims files `paper` names, every one loaded (so every error shows before anything plays).
pub fn load_claims(dir: &Path, paper: &str) -> Result<Vec<Claims>> {
    let paths: Vec<PathBuf> = if paper == "all" {
        let mut p: Vec<PathBuf> = std::fs::read_dir(dir)
            .map_err(|e| anyhow::anyhow!("{}: {e}", dir.display()))?
            .filter_map(|e| e.ok().map(|e| e.path()))
            .filter(|p| p.extension().is_some_and(|x| x == "ron"))
            .collect();
        p.sort();
        p
    } else {
        let p = dir.join(format!("{paper}.ron"));
        if !p.is_file() {
            bail!("no claims file {} for paper '{paper}'", p.display());
        }
        vec![p]
    };
    paths.iter().map(|p| Claims::load(p).map_err(anyhow::Error::from)).collect()
}

/// What the claims' statistics read from the run folders rather than frame records, added to
/// each played seed's run once per case: `FrameMs` less the shared passes a method would not
/// run alone (`not_run`), `PassMs` over its passes, and the statistics their methods compute
/// from the run's images (`folder_statistic`: SSS's PSNR against the claim's `against`
/// method, Fig. 7's image variance over its bound, σ by region), for the claims' statistics
/// and the cases' table columns.
fn add_from_folders(claims: &Claims, runs: &mut BTreeMap<String, CaseRuns>) -> Result<()> {
    let mut alone: Vec<&str> = Vec::new();
    let mut images: Vec<(&str, &str)> = Vec::new();
    let mut passes: Vec<(&str, &[String])> = Vec::new();
    add_columns(claims, runs)?;
    let of_claims =
        claims.claims.iter().filter_map(|c| c.case.as_deref().zip(c.statistic.as_ref()));
    let of_tables = claims.cases.iter().flat_map(|c| c.table.iter().map(|s| (c.name.as_str(), s)));
    for (case, s) in of_claims.chain(of_tables) {
        let Some(r) = runs.get_mut(case) else { continue };
        let at = |e: anyhow::Error| anyhow::anyhow!("case '{case}': {}: {e:#}", s.describe());
        if s.metric == Metric::PassMs && !passes.contains(&(case, &s.passes[..])) {
            passes.push((case, &s.passes));
            for seed in &mut r.seeds {
                super::pass_ms::add(seed, &s.passes).map_err(at)?;
            }
        }
        if let Some(statistic) = s.metric.from_images_by()
            && (s.against.is_some() || statistic.input != FolderInput::Against)
            && !images.contains(&(case, statistic.id))
        {
            images.push((case, statistic.id));
            let (frames, events) = (r.frames, r.events.clone());
            for seed in &mut r.seeds {
                super::folder_statistic::add(
                    seed,
                    &statistic,
                    frames,
                    &events,
                    s.against.as_deref(),
                )
                .map_err(at)?;
            }
        }
        if !s.not_run.is_empty() && !alone.contains(&case) {
            alone.push(case);
            for seed in &mut r.seeds {
                super::alone::leave_out(seed, &s.not_run).map_err(at)?;
            }
        }
    }
    Ok(())
}

/// The frames.csv columns (`frame_columns`) the claims' statistics, the cases' tables and
/// their `by_window` metrics read, once per case and metric.
fn add_columns(claims: &Claims, runs: &mut BTreeMap<String, CaseRuns>) -> Result<()> {
    let of_claims = claims
        .claims
        .iter()
        .filter_map(|c| c.case.as_deref().zip(c.statistic.as_ref().map(|s| s.metric)));
    let of_cases = claims.cases.iter().flat_map(|c| {
        let by = c.by_window.iter().flat_map(|b| b.metrics.iter().copied());
        c.table.iter().map(|s| s.metric).chain(by).map(|m| (c.name.as_str(), m))
    });
    let mut done: Vec<(&str, Metric)> = Vec::new();
    for (case, metric) in of_claims.chain(of_cases) {
        if !super::frame_columns::reads(metric) || done.contains(&(case, metric)) {
            continue;
        }
        done.push((case, metric));
        let Some(r) = runs.get_mut(case) else { continue };
        for seed in &mut r.seeds {
            super::frame_columns::add(seed, metric)
                .map_err(|e| anyhow::anyhow!("case '{case}': {}: {e:#}", metric.name()))?;
        }
    }
    Ok(())
}

/// How a paper's cases get their runs: played here, or read back from jobs run elsewhere.
pub(crate) type CaseSource<'a> =
    dyn FnMut(&Claims, &[Case], &str) -> Result<BTreeMap<String, CaseRuns>> + 'a;

/// The cases to play, and (case, played case) for each case whose runs would be another's: the
/// same scenario, seeds, sizes, methods and parameters (cases that differ only at another scale,
/// as the NIRC paper's two pre-training lengths at smoke scale). A run is deterministic, so the
/// second case's runs would be the same bits; they are played once.
pub(crate) fn same_runs(cases: &[Case]) -> (Vec<Case>, Vec<(String, String)>) {
    let runs_of = |c: &Case| Case { name: String::new(), entry: None, ..c.clone() };
    let mut played: Vec<Case> = Vec::new();
    let mut same = Vec::new();
    for c in cases {
        match played.iter().find(|p| runs_of(p) == runs_of(c)) {
            Some(p) => same.push((c.name.clone(), p.name.clone())),
            None => played.push(c.clone()),
        }
    }
    (played, same)
}

/// `flicker reproduce`: plays, judges, writes reproduce.md and reproduce.html.
pub fn reproduce(opts: &ReproduceOptions) -> Result<ReproduceOutcome> {
    let folder = opts.out.clone().unwrap_or_else(|| {
        PathBuf::from("runs").join(format!("reproduce_{}_{}", opts.paper, opts.scale.name()))
    });
    let mut play = |claims: &Claims, cases: &[Case], label: &str| {
        let out = folder.join(&claims.paper);
        play_cases(&claims.origin, cases, &out, &opts.cache_dir, opts.progress, label)
    };
    judge_papers(opts, &folder, &mut play)
}

/// Gets each paper's runs from `source`, judges every claim, writes reproduce.md and
/// reproduce.html to `folder`.
pub(crate) fn judge_papers(
    opts: &ReproduceOptions,
    folder: &Path,
    source: &mut CaseSource,
) -> Result<ReproduceOutcome> {
    if opts.seeds.is_some_and(|n| n < 2) {
        bail!("--seeds {}: an interval needs at least 2 seeds", opts.seeds.unwrap_or(0));
    }
    let started = std::time::Instant::now();
    let all = load_claims(&opts.claims_dir, &opts.paper)?;
    let folder = folder.to_path_buf();
    let mut papers = Vec::new();
    let mut outcomes = Vec::new();
    for claims in &all {
        let cases = claims.cases_for(opts.scale, opts.seeds);
        let label = format!("reproduce {}", claims.paper);
        let (played, same) = same_runs(&cases);
        let mut runs = source(claims, &played, &label)?;
        for (case, as_case) in same {
            if let Some(r) = runs.get(&as_case).cloned() {
                eprintln!(
                    "{label}: case {case}: the runs of case {as_case} (the same at this scale)"
                );
                runs.insert(case, r);
            }
        }
        for case in &claims.cases {
            if let Some(c) = &case.computation {
                eprintln!("{label}: case {} (computed: {})", case.name, c.name());
                runs.insert(
                    case.name.clone(),
                    c.runs(&claims.seeds_of(case, opts.scale, opts.seeds)),
                );
            }
        }
        add_from_folders(claims, &mut runs)?;
        let mut judged = Vec::new();
        for c in &claims.claims {
            let j = match (c.case.as_ref().and_then(|n| runs.get(n)), &c.statistic) {
                (Some(r), Some(s)) => {
                    let key = s.key();
                    judge(&c.comparison, &c.smallest_effect, &|m, w| {
                        r.per_seed_of(m, s.metric, &key, w.unwrap_or(&s.window))
                    })
                }
                _ => judge(&c.comparison, &c.smallest_effect, &|_, _| Err("not played".into())),
            };
            outcomes.push(ClaimOutcome {
                paper: claims.paper.clone(),
                id: c.id.clone(),
                declared_not_comparable: matches!(c.comparison, Comparison::NotComparable { .. }),
                timing: c.statistic.as_ref().is_some_and(|s| s.metric.is_timing()),
                judged: j.clone(),
            });
            judged.push((c, j));
        }
        let tables = case_tables(claims, &runs);
        papers.push(PaperResult { claims, judged, tables });
    }
    let seeds = opts.seeds.map_or("each case's own".to_string(), |n| n.to_string());
    let header = format!(
        "`flicker reproduce {} --scale {}` ({seeds} seeds) at {}. Each claim's interval lies between the one-sided 95% bounds of its per-seed effect (relations: the paired differences; log ratios: the geometric mean ratio; values, ratios and differences: their mean), judged against the claim's smallest effect that matters.",
        opts.paper,
        opts.scale.name(),
        stamp(&opts.claims_dir, &folder, started.elapsed())
    );
    let markdown = report::markdown(&header, &papers);
    frame::output::write_text(&folder.join("reproduce.md"), &markdown)?;
    frame::output::write_text(&folder.join("reproduce.html"), &report::html(&header, &papers))?;
    Ok(ReproduceOutcome { folder, markdown, claims: outcomes })
}

/// Where a table was made: the commit, the build profile, the adapter of its played runs, the
/// machine (cores, load average at the end) and the command's wall time.
pub fn stamp(claims_dir: &Path, folder: &Path, wall: std::time::Duration) -> String {
    let profile = if cfg!(debug_assertions) { "debug" } else { "release" };
    let cores = std::thread::available_parallelism().map_or(0, |n| n.get());
    let load = std::fs::read_to_string("/proc/loadavg")
        .ok()
        .map(|l| l.split_whitespace().take(3).collect::<Vec<_>>().join(" "))
        .unwrap_or_else(|| "unknown".into());
    format!(
        "commit {}, {profile} build, adapter {}, machine: {cores} cores, load average {load} at the end, {:.0} s wall",
        playback::manifest::commit(claims_dir),
        adapter_of(folder).unwrap_or_else(|| "none (computed cases only)".into()),
        wall.as_secs_f64()
    )
}

/// The adapter a played run's manifest.json names (the first found under `folder`).
fn adapter_of(folder: &Path) -> Option<String> {
    let mut dirs = vec![folder.to_path_buf()];
    while let Some(dir) = dirs.pop() {
        let mut entries: Vec<PathBuf> =
            std::fs::read_dir(&dir).ok()?.filter_map(|e| e.ok().map(|e| e.path())).collect();
        entries.sort();
        for path in entries {
            if path.is_dir() {
                dirs.push(path);
            } else if path.file_name().is_some_and(|n| n == "manifest.json") {
                let json: serde_json::Value =
                    serde_json::from_str(&std::fs::read_to_string(&path).ok()?).ok()?;
                let a = &json["adapter"];
                let field = |k: &str| a[k].as_str().unwrap_or_default().to_string();
                return Some(format!(
                    "{} ({}, {} {})",
                    field("name"),
                    field("backend"),
                    field("driver"),
                    field("driver_info")
                ));
            }
        }
    }
    None
}

/// The tables of the cases in `runs`, in the claims file's order of cases.
pub fn case_tables(claims: &Claims, runs: &BTreeMap<String, CaseRuns>) -> Vec<CaseTable> {
    let mut tables = Vec::new();
    for case in &claims.cases {
        let Some(r) = runs.get(&case.name) else { continue };
        let mut stats = Vec::new();
        let of_claims = claims
            .claims
            .iter()
            .filter(|c| c.case.as_deref() == Some(case.name.as_str()))
            .filter_map(|c| c.statistic.as_ref());
        for s in of_claims.chain(&case.table) {
            if !stats.contains(s) {
                stats.push(s.clone());
            }
        }
        let rows = r
            .methods()
            .into_iter()
            .map(|m| {
                let cells = stats
                    .iter()
                    .map(|s| cell(r.per_seed_of(&m, s.metric, &s.key(), &s.window)))
                    .collect();
                (m, cells)
            })
            .collect();
        if !stats.is_empty() {
            tables.push(CaseTable {
                case: case.name.clone(),
                seeds: r.seeds.len(),
                columns: stats.iter().map(|s| s.describe()).collect(),
                rows,
            });
        }
        tables.extend(case.by_window.iter().flat_map(|b| b.tables(&case.name, r)));
    }
    tables
}

#[cfg(test)]
mod tests {
    use super::*;

    fn case(name: &str, seeds: &[u64], frames: u32) -> Case {
        Case {
            name: name.into(),
            scenario: "a.ron".into(),
            measure: None,
            seeds: seeds.to_vec(),
            frames: Some(frames),
            resolution: Some((16, 9)),
            spp: None,
            methods: None,
            params: vec![("Nirc".into(), vec!["pretrain_frames".into()], 16.into())],
            entry: None,
        }
    }

    /// Cases with the same runs are played once; a case differing in anything played is not.
    #[test]
    fn cases_with_the_same_runs_are_played_once() {
        let (played, same) =
            same_runs(&[case("a", &[1, 2], 24), case("b", &[1, 2], 24), case("c", &[1, 3], 24)]);
        let names: Vec<&str> = played.iter().map(|c| c.name.as_str()).collect();
        assert_eq!(names, ["a", "c"]);
        assert_eq!(same, [("b".to_string(), "a".to_string())]);
        let mut d = case("d", &[1, 2], 24);
        d.params[0].2 = 1280.into();
        let (played, same) = same_runs(&[case("a", &[1, 2], 24), d, case("e", &[1, 2], 8)]);
        assert_eq!((played.len(), same.len()), (3, 0));
    }
}
