//! `flicker sweep plan SWEEP.ron --out DIR`: the job list (`DIR/plan.json`) and the executors'
//! files. Jobs are numbered in file order: cases, then parameter points (a grid row-major), then
//! seeds. plan.json holds no time, no host and no path under DIR, so the same sweep file plans
//! the same bytes wherever DIR is; every job's input is checked (scenario, method labels,
//! parameter names and types) before anything is written, errors at the sweep file's line.

use std::path::{Path, PathBuf};

use anyhow::{Context, Result, anyhow, bail};
use serde::{Deserialize, Serialize};

use super::param;
use super::spec::{Point, Sweep};
use crate::suite::run::case_spec;
use crate::suite::spec::Case;
use playback::play::{Overrides, RunSpec};

/// One job: one case at one parameter point and one seed, one run folder.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Job {
    pub index: usize,
    pub case: String,
    pub scenario: PathBuf,
    pub seed: u64,
    pub frames: Option<u32>,
    pub resolution: Option<(u32, u32)>,
    pub spp: Option<u32>,
    pub methods: Option<Vec<String>>,
    /// The point's label, e.g. `taa.alpha=0.1`.
    pub point: String,
    pub params: Vec<(String, serde_json::Value)>,
    /// The run folder, relative to the sweep's folder.
    pub folder: PathBuf,
    /// The case's own parameters (`flicker reproduce --plan`: a scale's `set`), applied before
    /// `params`.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub case_params: Vec<(String, Vec<String>, serde_json::Value)>,
}

#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Plan {
    pub sweep: String,
    /// The sweep file (absolute).
    pub file: PathBuf,
    /// Reference cache of every job; `None`: `DIR/cache`, shared by the jobs.
    pub cache_dir: Option<PathBuf>,
    pub jobs: Vec<Job>,
    /// Each job's record keeps its per-frame metrics (`flicker reproduce --judge-from` reads
    /// them); a sweep's jobs keep only their means.
    #[serde(default, skip_serializing_if = "std::ops::Not::not")]
    pub keep_frames: bool,
}

pub const PLAN_FILE: &str = "plan.json";

/// A job's finished record (`DIR/done/job_NNNN.json`); its absence marks the job as pending.
pub fn done_file(dir: &Path, index: usize) -> PathBuf {
    dir.join("done").join(format!("job_{index:04}.json"))
}

pub fn log_file(dir: &Path, index: usize) -> PathBuf {
    dir.join("logs").join(format!("job_{index:04}.log"))
}

impl Plan {
    pub fn load(dir: &Path) -> Result<Plan> {
        let path = dir.join(PLAN_FILE);
        let text = std::fs::read_to_string(&path).with_context(|| {
            format!(
                "reading {} (plan the sweep first: `flicker sweep plan SWEEP.ron --out {}`)",
                path.display(),
                dir.display()
            )
        })?;
        serde_json::from_str(&text).with_context(|| format!("parsing {}", path.display()))
    }

    pub fn cache_dir(&self, dir: &Path) -> PathBuf {
        self.cache_dir.clone().unwrap_or_else(|| dir.join("cache"))
    }
}

impl Job {
    fn case(&self) -> Case {
        Case {
            name: self.case.clone(),
            scenario: self.scenario.clone(),
            measure: None,
            seeds: vec![self.seed],
            frames: self.frames,
            resolution: self.resolution,
            spp: self.spp,
            methods: self.methods.clone(),
            params: self.case_params.clone(),
            entry: None,
        }
    }

    /// The job's run: the case's overrides, then its parameters; output in `dir/folder`.
    pub fn spec(&self, plan: &Plan, dir: &Path) -> Result<(RunSpec, Overrides)> {
        let (mut spec, overrides) =
            case_spec(&plan.file, &self.case(), self.seed, &dir.join(&self.folder))?;
        for (p, v) in &self.params {
            param::apply(&mut spec.methods, p, v)
                .map_err(|e| anyhow!("{}: job {}: {e}", plan.file.display(), self.index))?;
        }
        Ok((spec, overrides))
    }
}

/// Checks that the point applies to the case (at the sweep file's line of the offending entry).
fn check_point(sweep: &Sweep, case: &Case, point: &Point) -> Result<()> {
    let (mut spec, _) = case_spec(&sweep.origin, case, case.seeds[0], Path::new("unused"))?;
    for (i, s) in point.settings.iter().enumerate() {
        if let Err(e) = param::apply(&mut spec.methods, &s.param, &s.value) {
            let entry = point.entries.get(i).or(point.entries.first());
            let (line, col) = entry.map_or((1, 1), |e| (e.line, e.column));
            bail!("{}:{line}:{col}: case '{}': {e}", sweep.origin.display(), case.name);
        }
    }
    playback::methods::check_labels(&spec.scenario, &spec.methods)
        .map_err(|e| anyhow!("{}: point {}: {e}", sweep.origin.display(), point.label()))?;
    Ok(())
}

/// The jobs of a sweep, in order; every job's input checked.
pub fn jobs(sweep: &Sweep) -> Result<Vec<Job>> {
    let mut jobs = Vec::new();
    for case in &sweep.cases {
        let scenario = std::fs::canonicalize(&case.scenario).map_err(|e| {
            let (line, col) = case.entry.as_ref().map_or((1, 1), |e| (e.line, e.column));
            anyhow!(
                "{}:{line}:{col}: case '{}': scenario {}: {e}",
                sweep.origin.display(),
                case.name,
                case.scenario.display()
            )
        })?;
        for point in &sweep.points {
            check_point(sweep, case, point)?;
            for &seed in &case.seeds {
                let index = jobs.len();
                jobs.push(Job {
                    index,
                    case: case.name.clone(),
                    scenario: scenario.clone(),
                    seed,
                    frames: case.frames,
                    resolution: case.resolution,
                    spp: case.spp,
                    methods: case.methods.clone(),
                    point: point.label(),
                    params: point
                        .settings
                        .iter()
                        .map(|s| (s.param.clone(), s.value.clone()))
                        .collect(),
                    folder: PathBuf::from("runs").join(format!("job_{index:04}")),
                    case_params: Vec::new(),
                });
            }
        }
    }
    Ok(jobs)
}

/// Single-quoted for sh.
pub fn shell_quote(p: &Path) -> String {
    format!("'{}'", p.display().to_string().replace('\'', "'\\''"))
}

/// Writes `DIR/plan.json`, `DIR/jobs.txt` (GNU parallel) and `DIR/sweep.sbatch` (Slurm array);
/// `exe` is the flicker program the executors start. Planning again into the same folder is
/// allowed when the plan is the same (finished jobs stay finished); another plan is refused.
pub fn plan(sweep_file: &Path, dir: &Path, cache_dir: Option<PathBuf>, exe: &Path) -> Result<Plan> {
    let sweep = Sweep::load(sweep_file)?;
    let jobs = jobs(&sweep)?;
    let file = std::fs::canonicalize(sweep_file)?;
    let plan = Plan { sweep: sweep.name.clone(), file, cache_dir, jobs, keep_frames: false };
    write(&plan, dir, exe)?;
    Ok(plan)
}

/// Writes `plan` as `DIR/plan.json` with the executors' files `DIR/jobs.txt` and
/// `DIR/sweep.sbatch`; refused where DIR holds another plan.
pub fn write(plan: &Plan, dir: &Path, exe: &Path) -> Result<()> {
    let text = serde_json::to_string_pretty(&plan)? + "\n";
    let path = dir.join(PLAN_FILE);
    if let Ok(old) = std::fs::read_to_string(&path)
        && old != text
    {
        bail!(
            "{} holds another sweep's plan; choose another --out or remove the folder",
            dir.display()
        );
    }
    std::fs::create_dir_all(dir).with_context(|| format!("creating {}", dir.display()))?;
    let dir = std::fs::canonicalize(dir)?;
    frame::output::write_text(&path, &text)?;
    let exe = std::fs::canonicalize(exe).unwrap_or_else(|_| exe.to_path_buf());
    let job_line = |i: usize| {
        format!("{} sweep job {} --index {i} --quiet", shell_quote(&exe), shell_quote(&dir))
    };
    // GNU parallel: `parallel --jobs N < jobs.txt`, or over hosts with `--sshloginfile`.
    let lines: String = plan
        .jobs
        .iter()
        .map(|j| {
            format!("{} > {} 2>&1\n", job_line(j.index), shell_quote(&log_file(&dir, j.index)))
        })
        .collect();
    frame::output::write_text(&dir.join("jobs.txt"), &lines)?;
    std::fs::create_dir_all(dir.join("logs"))?;
    frame::output::write_text(&dir.join("sweep.sbatch"), &sbatch(plan, &dir, &exe))?;
    Ok(())
}

/// The Slurm array script: task i runs job i. `sbatch --array=3,5 sweep.sbatch` reruns jobs 3
/// and 5 alone (the command line's --array wins over the script's).
fn sbatch(plan: &Plan, dir: &Path, exe: &Path) -> String {
    let last = plan.jobs.len().saturating_sub(1);
    format!(
        "#!/bin/bash\n\
         #SBATCH --job-name=flicker-{name}\n\
         #SBATCH --array=0-{last}\n\
         #SBATCH --ntasks=1\n\
         #SBATCH --cpus-per-task=1\n\
         #SBATCH --output={logs}/slurm_%A_%a.out\n\
         # One array task = one job of {plan_file}; its run folder goes to {dir}/runs/.\n\
         set -euo pipefail\n\
         exec {exe} sweep job {qdir} --index \"$SLURM_ARRAY_TASK_ID\" --quiet\n",
        name = plan.sweep,
        logs = dir.join("logs").display(),
        plan_file = dir.join(PLAN_FILE).display(),
        dir = dir.display(),
        exe = shell_quote(exe),
        qdir = shell_quote(dir),
    )
}
