//! `flicker sweep merge DIR`: the finished jobs' records gathered per configuration (case,
//! parameter point, method) over seeds into `DIR/summary.json`, one speed-vs-accuracy chart
//! across all configurations with the Pareto front (`DIR/speed_vs_ACCURACY.svg` and `.png`,
//! drawn by the report crate) and `DIR/report.md`. Everything but the `timing` entries is a
//! function of the runs' images, so a sweep merged from local and from Slurm jobs agrees there.

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

use anyhow::{Context, Result, bail};
use report::charts::{Chart, Kind, Series, pareto_front, plot};
use serde::{Deserialize, Serialize};

use super::job::JobRecord;
use super::plan::{Plan, done_file};

#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Stat {
    pub mean: f64,
    /// Sample standard deviation over seeds (0 with one seed).
    pub sd: f64,
    pub per_seed: Vec<f64>,
}

impl Stat {
    fn of(values: Vec<f64>) -> Option<Stat> {
        if values.is_empty() {
            return None;
        }
        let n = values.len() as f64;
        let mean = values.iter().sum::<f64>() / n;
        let sd = if values.len() > 1 {
            (values.iter().map(|v| (v - mean).powi(2)).sum::<f64>() / (n - 1.0)).sqrt()
        } else {
            0.0
        };
        Some(Stat { mean, sd, per_seed: values })
    }
}

#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Timing {
    pub ms_per_frame: Option<Stat>,
    /// On the Pareto front of time against the accuracy metric (fastest for its accuracy).
    pub on_pareto_front: bool,
}

#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Configuration {
    pub case: String,
    pub point: String,
    pub params: Vec<(String, serde_json::Value)>,
    pub method: String,
    /// The chart's and the report's name of it.
    pub label: String,
    pub seeds: Vec<u64>,
    pub jobs: Vec<usize>,
    /// metric -> statistics over seeds of the per-seed means over frames.
    pub metrics: BTreeMap<String, Option<Stat>>,
    pub rays_per_frame: Option<Stat>,
    /// Not deterministic: compare sweeps without it.
    pub timing: Timing,
}

#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct SweepSummary {
    pub sweep: String,
    pub file: PathBuf,
    pub jobs: usize,
    /// The chart's accuracy axis.
    pub accuracy: String,
    pub configurations: Vec<Configuration>,
}

pub struct Merged {
    pub summary: SweepSummary,
    pub summary_file: PathBuf,
    pub chart: PathBuf,
    pub report: PathBuf,
}

/// The records of every job; a missing one is an error naming the commands that rerun it.
fn records(dir: &Path, plan: &Plan) -> Result<Vec<JobRecord>> {
    let missing: Vec<usize> =
        plan.jobs.iter().map(|j| j.index).filter(|&i| !done_file(dir, i).exists()).collect();
    if !missing.is_empty() {
        let list = missing.iter().map(usize::to_string).collect::<Vec<_>>().join(",");
        bail!(
            "{}: {} of {} jobs have not finished ({list}); rerun them with `flicker sweep local {0}` (all pending), `flicker sweep job {0} --index I`, or `sbatch --array={list} {0}/sweep.sbatch`; their logs are in {0}/logs/",
            dir.display(),
            missing.len(),
            plan.jobs.len()
        );
    }
    plan.jobs
        .iter()
        .map(|j| {
            let path = done_file(dir, j.index);
            let r: JobRecord = serde_json::from_str(&std::fs::read_to_string(&path)?)
                .with_context(|| format!("parsing {}", path.display()))?;
            Ok(r)
        })
        .collect()
}

pub fn merge(dir: &Path) -> Result<Merged> {
    let plan = Plan::load(dir)?;
    let records = records(dir, &plan)?;
    // Configurations in job order.
    let mut order: Vec<(String, String, String)> = Vec::new();
    let mut groups: BTreeMap<
        (String, String, String),
        Vec<(&JobRecord, &super::job::MethodNumbers)>,
    > = BTreeMap::new();
    for r in &records {
        for (method, numbers) in &r.methods {
            let key = (r.case.clone(), r.point.clone(), method.clone());
            if !groups.contains_key(&key) {
                order.push(key.clone());
            }
            groups.entry(key).or_default().push((r, numbers));
        }
    }
    let many_cases = plan.jobs.iter().any(|j| j.case != plan.jobs[0].case);
    let many_methods = order.iter().any(|k| k.2 != order[0].2);
    let mut configurations: Vec<Configuration> = order
        .iter()
        .map(|key| {
            let rows = &groups[key];
            let metric_names: Vec<String> = rows[0].1.metrics.keys().cloned().collect();
            let metrics = metric_names
                .into_iter()
                .map(|m| {
                    let values: Option<Vec<f64>> =
                        rows.iter().map(|(_, n)| n.metrics.get(&m).copied().flatten()).collect();
                    (m, values.and_then(Stat::of))
                })
                .collect();
            let all = |f: fn(&super::job::MethodNumbers) -> Option<f64>| {
                rows.iter().map(|(_, n)| f(n)).collect::<Option<Vec<f64>>>().and_then(Stat::of)
            };
            let mut label = Vec::new();
            if many_cases {
                label.push(key.0.clone());
            }
            if many_methods {
                label.push(key.2.clone());
            }
            label.push(key.1.clone());
            Configuration {
                case: key.0.clone(),
                point: key.1.clone(),
                params: rows[0].0.params.clone(),
                method: key.2.clone(),
                label: label.join(" "),
                seeds: rows.iter().map(|(r, _)| r.seed).collect(),
                jobs: rows.iter().map(|(r, _)| r.index).collect(),
                metrics,
                rays_per_frame: all(|n| n.rays_per_frame),
                timing: Timing { ms_per_frame: all(|n| n.ms_per_frame), on_pareto_front: false },
            }
        })
        .collect();
    // Accuracy: FLIP against the reference where every configuration has it.
    let has =
        |m: &str| configurations.iter().all(|c| c.metrics.get(m).is_some_and(Option::is_some));
    let accuracy =
        ["flip", "mse", "smape"].into_iter().find(|m| has(m)).unwrap_or("flip").to_string();
    let point_of = |c: &Configuration| -> (f64, f64) {
        (
            c.timing.ms_per_frame.as_ref().map_or(f64::NAN, |s| s.mean),
            c.metrics.get(&accuracy).cloned().flatten().map_or(f64::NAN, |s| s.mean),
        )
    };
    let points: Vec<(f64, f64)> = configurations.iter().map(point_of).collect();
    let front = pareto_front(&points);
    for c in &mut configurations {
        let p = point_of(c);
        c.timing.on_pareto_front = front.contains(&p);
    }
    let summary = SweepSummary {
        sweep: plan.sweep.clone(),
        file: plan.file.clone(),
        jobs: plan.jobs.len(),
        accuracy: accuracy.clone(),
        configurations,
    };
    let summary_file = dir.join("summary.json");
    frame::output::write_json(&summary_file, &summary)?;

    let chart = Chart {
        title: format!("Speed vs accuracy ({}) — sweep {}", accuracy.to_uppercase(), plan.sweep),
        x_label: "mean ms per frame".into(),
        y_label: format!("mean {accuracy}"),
        kind: Kind::Scatter,
        series: summary
            .configurations
            .iter()
            .zip(&points)
            .map(|(c, p)| Series { name: c.label.clone(), points: vec![*p] })
            .collect(),
        events: vec![],
        pareto: front,
        x_extent: vec![],
    };
    let stem = format!("speed_vs_{accuracy}");
    let (svg, _) = plot::to_svg(&chart)?;
    let chart_file = dir.join(format!("{stem}.svg"));
    frame::output::write_text(&chart_file, &svg)?;
    let png = plot::to_png(&chart)?;
    frame::output::write_atomic(&dir.join(format!("{stem}.png")), |w| Ok(w.write_all(&png)?))?;
    let report = dir.join("report.md");
    frame::output::write_text(&report, &markdown(&summary, &stem))?;
    Ok(Merged { summary, summary_file, chart: chart_file, report })
}

fn cell(s: &Option<Stat>, digits: usize) -> String {
    match s {
        Some(s) if s.per_seed.len() > 1 => format!("{:.digits$} ± {:.digits$}", s.mean, s.sd),
        Some(s) => format!("{:.digits$}", s.mean),
        None => "-".into(),
    }
}

fn markdown(s: &SweepSummary, chart: &str) -> String {
    let mut md = format!(
        "# Sweep {}\n\n{} jobs from {}. Means over seeds ± their standard deviation; FLIP, MSE against the reference, \
         SMAPE against the previous frame, each a mean over the recorded frames. ◆ marks the Pareto front of time against {}.\n\n\
         ![speed vs accuracy]({chart}.svg)\n\n| configuration | case | method | seeds | FLIP | SMAPE | MSE | rays/frame | ms/frame | Pareto |\n|---|---|---|---:|---:|---:|---:|---:|---:|:---:|\n",
        s.sweep,
        s.jobs,
        s.file.display(),
        s.accuracy.to_uppercase()
    );
    for c in &s.configurations {
        let m = |k: &str| c.metrics.get(k).cloned().flatten();
        md.push_str(&format!(
            "| {} | {} | {} | {} | {} | {} | {} | {} | {} | {} |\n",
            c.point,
            c.case,
            c.method,
            c.seeds.len(),
            cell(&m("flip"), 4),
            cell(&m("smape"), 4),
            cell(&m("mse"), 5),
            cell(&c.rays_per_frame, 0),
            cell(&c.timing.ms_per_frame, 2),
            if c.timing.on_pareto_front { "◆" } else { "" }
        ));
    }
    md
}
