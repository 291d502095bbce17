//! Paper scale beyond one machine: `flicker reproduce PAPER --plan DIR` writes every case's
//! seeds as the jobs of a sweep (`DIR/plan.json`, `DIR/jobs.txt` for GNU parallel,
//! `DIR/sweep.sbatch` for a Slurm array; each job runs as `flicker sweep job DIR --index I`,
//! or all with `flicker sweep local DIR`), each job's record keeping its per-frame metrics;
//! `flicker reproduce PAPER --judge-from DIR` judges once every job has finished, as a run
//! played here would be judged. Computed cases are computed by the judge.

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

use anyhow::{Context, Result, anyhow, bail};
use serde::{Deserialize, Serialize};

use super::run::{ReproduceOptions, ReproduceOutcome, judge_papers, load_claims};
use crate::suite::measurement::CaseRuns;
use crate::suite::run::case_spec;
use crate::sweep::job::JobRecord;
use crate::sweep::plan::{Job, Plan, done_file};

/// What `DIR` was planned for, and which paper, case and seed each job plays.
pub const META_FILE: &str = "reproduce.json";

#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct PlannedJob {
    pub index: usize,
    pub paper: String,
    pub case: String,
    pub seed: u64,
}

#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Meta {
    pub paper: String,
    pub scale: String,
    pub seeds: Option<usize>,
    pub jobs: Vec<PlannedJob>,
}

impl Meta {
    fn command(&self) -> String {
        let seeds = self.seeds.map_or(String::new(), |n| format!(" --seeds {n}"));
        format!("flicker reproduce {} --scale {}{seeds}", self.paper, self.scale)
    }
}

/// Writes the jobs of `opts` (paper, scale, seeds) into `dir`; every case's input is checked
/// first, errors at the claims file's line. `exe` is the flicker the executors start.
pub fn plan(opts: &ReproduceOptions, dir: &Path, exe: &Path) -> Result<(Plan, Meta)> {
    if opts.seeds.is_some_and(|n| n < 2) {
        bail!("--seeds {}: an interval needs at least 2 seeds", opts.seeds.unwrap_or(0));
    }
    let all = load_claims(&opts.claims_dir, &opts.paper)?;
    let mut jobs = Vec::new();
    let mut planned = Vec::new();
    for claims in &all {
        // A case whose runs are another's at this scale is judged on that one's (`same_runs`).
        for case in super::run::same_runs(&claims.cases_for(opts.scale, opts.seeds)).0 {
            let scenario = std::fs::canonicalize(&case.scenario).map_err(|e| {
                anyhow!(
                    "{}: case '{}': {}: {e}",
                    claims.origin.display(),
                    case.name,
                    case.scenario.display()
                )
            })?;
            for &seed in &case.seeds {
                // Checked here, so that a bad case fails the plan, not a job on the cluster.
                case_spec(&claims.origin, &case, seed, Path::new("unused"))?;
                let index = jobs.len();
                let folder = PathBuf::from("runs")
                    .join(&claims.paper)
                    .join(&case.name)
                    .join(format!("seed_{seed}"));
                jobs.push(Job {
                    index,
                    case: format!("{}/{}", claims.paper, case.name),
                    scenario: scenario.clone(),
                    seed,
                    frames: case.frames,
                    resolution: case.resolution,
                    spp: case.spp,
                    methods: case.methods.clone(),
                    point: opts.scale.name().to_string(),
                    params: Vec::new(),
                    folder,
                    case_params: case.params.clone(),
                });
                planned.push(PlannedJob {
                    index,
                    paper: claims.paper.clone(),
                    case: case.name.clone(),
                    seed,
                });
            }
        }
    }
    let file = match all.as_slice() {
        [one] => one.origin.clone(),
        _ => opts.claims_dir.clone(),
    };
    let plan = Plan {
        sweep: format!("reproduce-{}-{}", opts.paper, opts.scale.name()),
        file: std::fs::canonicalize(&file).unwrap_or(file),
        cache_dir: opts.cache_dir.clone(),
        jobs,
        keep_frames: true,
    };
    let meta = Meta {
        paper: opts.paper.clone(),
        scale: opts.scale.name().to_string(),
        seeds: opts.seeds,
        jobs: planned,
    };
    crate::sweep::plan::write(&plan, dir, exe)?;
    frame::output::write_text(
        &dir.join(META_FILE),
        &(serde_json::to_string_pretty(&meta)? + "\n"),
    )?;
    Ok((plan, meta))
}

/// Judges the jobs planned in `dir` (all finished) as `flicker reproduce` judges runs it
/// played; reproduce.md and reproduce.html go to `--out` or `dir`.
pub fn judge_from(opts: &ReproduceOptions, dir: &Path) -> Result<ReproduceOutcome> {
    let meta_file = dir.join(META_FILE);
    let text = std::fs::read_to_string(&meta_file).with_context(|| {
        format!(
            "reading {} (plan the jobs first: `flicker reproduce {} --scale {} --plan {}`)",
            meta_file.display(),
            opts.paper,
            opts.scale.name(),
            dir.display()
        )
    })?;
    let meta: Meta =
        serde_json::from_str(&text).with_context(|| format!("parsing {}", meta_file.display()))?;
    if meta.paper != opts.paper || meta.scale != opts.scale.name() || meta.seeds != opts.seeds {
        bail!(
            "{} holds the jobs of `{}`; judge them with the same paper, --scale and --seeds",
            dir.display(),
            meta.command()
        );
    }
    let plan = Plan::load(dir)?;
    let missing: Vec<String> = plan
        .jobs
        .iter()
        .filter(|j| !done_file(dir, j.index).exists())
        .map(|j| j.index.to_string())
        .collect();
    if !missing.is_empty() {
        let list = missing.join(",");
        bail!(
            "{}: {} of {} jobs have not finished ({list}); run them with `flicker sweep local {0}`, `flicker sweep job {0} --index I` or `sbatch --array={list} {0}/sweep.sbatch`; their logs are in {0}/logs/",
            dir.display(),
            missing.len(),
            plan.jobs.len()
        );
    }
    let folder = opts.out.clone().unwrap_or_else(|| dir.to_path_buf());
    let mut read_back = |claims: &super::Claims,
                         cases: &[crate::suite::spec::Case],
                         label: &str|
     -> Result<BTreeMap<String, CaseRuns>> {
        let mut runs: BTreeMap<String, CaseRuns> = BTreeMap::new();
        for case in cases {
            for &seed in &case.seeds {
                let job = meta
                    .jobs
                    .iter()
                    .find(|j| j.paper == claims.paper && j.case == case.name && j.seed == seed)
                    .ok_or_else(|| {
                        anyhow!(
                            "{}: no job plays case '{}' seed {seed} of {}; plan again",
                            dir.display(),
                            case.name,
                            claims.paper
                        )
                    })?;
                let path = done_file(dir, job.index);
                let record: JobRecord = serde_json::from_str(&std::fs::read_to_string(&path)?)
                    .with_context(|| format!("parsing {}", path.display()))?;
                let played = record.played.ok_or_else(|| {
                    anyhow!("{}: job {} kept no frames; plan again", path.display(), job.index)
                })?;
                eprintln!("{label}: case {} seed {seed} (job {})", case.name, job.index);
                let r = runs.entry(case.name.clone()).or_default();
                r.frames = played.frames;
                r.events = played.events;
                let mut run = played.run;
                run.folder = Some(dir.join(&plan.jobs[job.index].folder));
                r.seeds.push(run);
            }
        }
        Ok(runs)
    };
    judge_papers(opts, &folder, &mut read_back)
}
