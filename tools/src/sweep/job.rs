//! `flicker sweep job DIR --index I`: one job of a planned sweep (what every executor runs):
//! its run folder under `DIR/runs/`, then its record `DIR/done/job_NNNN.json` (per method, the
//! mean of each metric over the recorded frames, rays and time per frame). The record is
//! removed first and written last, so a failed job stays pending.

use std::collections::BTreeMap;
use std::path::Path;
use std::time::Instant;

use anyhow::{Result, anyhow};
use serde::{Deserialize, Serialize};

use super::plan::{Plan, done_file};
use crate::suite::measurement::SeedRun;
use crate::suite::metric::Metric;
use frame::frame_record::FrameRecord;
use playback::play::{RunOptions, run_spec};

/// One method's numbers in one job.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct MethodNumbers {
    /// metric name -> mean over the frames that have it (`None`: no frame has it).
    pub metrics: BTreeMap<String, Option<f64>>,
    /// Rays traced per frame (the GPU counters; deterministic).
    pub rays_per_frame: Option<f64>,
    /// Time per frame: the sum of the method's pass times, mean over frames (not deterministic).
    pub ms_per_frame: Option<f64>,
}

#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct JobRecord {
    pub index: usize,
    pub case: String,
    pub point: String,
    pub params: Vec<(String, serde_json::Value)>,
    pub seed: u64,
    /// method label -> numbers
    pub methods: BTreeMap<String, MethodNumbers>,
    pub wall_s: f64,
    /// The per-frame metrics, where the plan keeps them (`Plan::keep_frames`).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub played: Option<Played>,
}

/// A job's run as a suite keeps it: its frames and events (recorded frames) and each
/// method's per-frame metrics, so that a judge elsewhere reads what a played case would hold.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Played {
    pub frames: u32,
    pub events: Vec<u32>,
    pub run: SeedRun,
}

fn mean(values: impl Iterator<Item = Option<f64>>) -> Option<f64> {
    let v: Vec<f64> = values.flatten().filter(|x| x.is_finite()).collect();
    (!v.is_empty()).then(|| v.iter().sum::<f64>() / v.len() as f64)
}

/// A frame's time: its passes' sum when every pass was timed, else the CPU time.
fn frame_ms(r: &FrameRecord) -> f64 {
    r.passes_total_ms().unwrap_or(r.cpu_ms)
}

pub fn numbers(records: &[FrameRecord]) -> BTreeMap<String, MethodNumbers> {
    let mut by_method: BTreeMap<String, Vec<&FrameRecord>> = BTreeMap::new();
    for r in records {
        by_method.entry(r.method.clone()).or_default().push(r);
    }
    by_method
        .into_iter()
        .map(|(label, mut rows)| {
            rows.sort_by_key(|r| r.frame);
            // Times are kept apart (ms_per_frame, the summary's `timing`): they differ run to run.
            let metrics = Metric::all()
                .iter()
                .filter(|m| !m.is_timing())
                .map(|m| (m.name().to_string(), mean(rows.iter().map(|r| m.of(r)))))
                .collect();
            let numbers = MethodNumbers {
                metrics,
                rays_per_frame: mean(rows.iter().map(|r| r.rays.map(|x| x as f64))),
                ms_per_frame: mean(rows.iter().map(|r| Some(frame_ms(r)))),
            };
            (label, numbers)
        })
        .collect()
}

/// Adds each method's JOD over the whole run, from the run's summary.json (report::jod).
fn with_jod(
    mut numbers: BTreeMap<String, MethodNumbers>,
    run: &Path,
) -> BTreeMap<String, MethodNumbers> {
    let summary: Option<serde_json::Value> = std::fs::read_to_string(run.join("summary.json"))
        .ok()
        .and_then(|t| serde_json::from_str(&t).ok());
    for m in summary.iter().flat_map(|s| s["methods"].as_array().into_iter().flatten()) {
        let (Some(label), Some(jod)) = (m["method"].as_str(), m["jod"]["overall"].as_f64()) else {
            continue;
        };
        if let Some(n) = numbers.get_mut(label) {
            n.metrics.insert(Metric::Cvvdp.name().to_string(), Some(jod));
        }
    }
    numbers
}

pub fn run_job(dir: &Path, index: usize, progress: bool) -> Result<JobRecord> {
    let plan = Plan::load(dir)?;
    let job = plan.jobs.get(index).ok_or_else(|| {
        anyhow!(
            "{}: no job {index}; the plan has jobs 0-{}",
            dir.display(),
            plan.jobs.len().saturating_sub(1)
        )
    })?;
    let done = done_file(dir, index);
    if done.exists() {
        std::fs::remove_file(&done)?;
    }
    let (spec, overrides) = job.spec(&plan, dir)?;
    eprintln!(
        "sweep {}: job {index}: case {} {} seed {}",
        plan.sweep, job.case, job.point, job.seed
    );
    let start = Instant::now();
    let opts = RunOptions {
        scenario: job.scenario.clone(),
        overrides,
        cache_dir: Some(plan.cache_dir(dir)),
        progress,
    };
    let summary = run_spec(&spec, &opts).map_err(|e| {
        anyhow!("job {index} (case {} {} seed {}): {e:#}", job.case, job.point, job.seed)
    })?;
    let record = JobRecord {
        index,
        case: job.case.clone(),
        point: job.point.clone(),
        params: job.params.clone(),
        seed: job.seed,
        methods: with_jod(numbers(&summary.records), &summary.folder),
        wall_s: start.elapsed().as_secs_f64(),
        played: plan.keep_frames.then(|| Played {
            frames: spec.scenario.frames,
            events: crate::suite::run::event_frames(&spec.scenario),
            run: SeedRun::from_records(job.seed, &summary.records),
        }),
    };
    frame::output::write_json(&done, &record)?;
    Ok(record)
}
