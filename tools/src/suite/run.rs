//! Playing a suite: every case once per seed through `playback`, then each gate judged for
//! each (case, method) it applies to; `bless` stores the measurements as the adapter's baseline.

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

use anyhow::{Result, anyhow, bail};
use render::gpu::Gpu;

use super::baseline::{Baseline, BaselineFile, adapter_key, now};
use super::gate::{GateResult, judge};
use super::measurement::{CaseRuns, SeedRun};
use super::spec::{Bound, Case, Gate, Suite};
use super::{junit, markdown};
use crate::measure::{MeasureOptions, Measured};
use playback::play::{Overrides, RunOptions, RunSpec, run_spec};

pub struct SuiteOptions {
    pub suite: PathBuf,
    /// Where case runs, summary.md and junit.xml go [default: runs/suite_NAME].
    pub out: Option<PathBuf>,
    /// Reference cache [default: the usual location].
    pub cache_dir: Option<PathBuf>,
    /// The baseline file [default: baselines/NAME.json next to the suite file].
    pub baselines: Option<PathBuf>,
    pub progress: bool,
}

pub struct SuiteOutcome {
    pub results: Vec<GateResult>,
    pub folder: PathBuf,
    pub summary: PathBuf,
    pub junit: PathBuf,
    /// The summary's text.
    pub markdown: String,
}

impl SuiteOutcome {
    pub fn passed(&self) -> bool {
        self.results.iter().all(GateResult::passed)
    }
}

struct Prepared {
    suite: Suite,
    folder: PathBuf,
    baselines: PathBuf,
    adapter: render::gpu::AdapterSummary,
}

fn prepare(opts: &SuiteOptions) -> Result<Prepared> {
    let suite = Suite::load(&opts.suite)?;
    let folder = opts
        .out
        .clone()
        .unwrap_or_else(|| PathBuf::from("runs").join(format!("suite_{}", suite.name)));
    let baselines = opts.baselines.clone().unwrap_or_else(|| suite.baseline_file());
    // The adapter keys the baseline; asked before anything plays so that a missing baseline
    // is reported at once. Frames from disk are measured on the CPU: a suite of only those
    // needs no GPU, and its baseline is the frames' alone.
    let adapter = if suite.cases.iter().all(|c| c.measure.is_some()) {
        measured_frames_adapter()
    } else {
        Gpu::new()?.summary
    };
    Ok(Prepared { suite, folder, baselines, adapter })
}

/// What keys the baseline of a suite whose cases are all frames from disk.
fn measured_frames_adapter() -> render::gpu::AdapterSummary {
    render::gpu::AdapterSummary {
        name: "frames from disk".into(),
        backend: "cpu".into(),
        driver: String::new(),
        driver_info: String::new(),
        device_type: "Cpu".into(),
    }
}

/// `FILE:LINE:COLUMN: case 'NAME'`, where errors about a case start.
fn case_at(origin: &Path, case: &Case) -> String {
    let (line, column) = case.entry.as_ref().map_or((1, 1), |e| (e.line, e.column));
    format!("{}:{line}:{column}: case '{}'", origin.display(), case.name)
}

/// A case's run at one seed, its methods filtered; input errors point at the case's line in
/// `origin` (the suite or sweep file).
pub(crate) fn case_spec(
    origin: &Path,
    case: &Case,
    seed: u64,
    out: &Path,
) -> Result<(RunSpec, Overrides)> {
    let at = case_at(origin, case);
    let overrides = Overrides {
        frames: case.frames,
        resolution: case.resolution,
        spp: case.spp,
        seed: Some(seed),
        out: Some(out.to_path_buf()),
    };
    let scenario = sim::Scenario::load(&case.scenario).map_err(|e| anyhow!("{at}: {e}"))?;
    let mut spec =
        RunSpec::from_scenario(scenario, &overrides).map_err(|e| anyhow!("{at}: {e}"))?;
    if let Some(keep) = &case.methods {
        let labels: Vec<String> = spec.methods.iter().map(|m| m.label()).collect();
        if let Some(unknown) = keep.iter().find(|k| !labels.contains(k)) {
            bail!(
                "{at}: no method labelled '{unknown}' in {}; its methods are: {}",
                case.scenario.display(),
                labels.join(", ")
            );
        }
        spec.methods.retain(|m| keep.contains(&m.label()));
    }
    crate::sweep::param::set_each(&mut spec.methods, &case.params)
        .map_err(|e| anyhow!("{at}: {e}"))?;
    if !case.params.is_empty() {
        // A parameter may change a label (`spp`); two equal ones would share a run column.
        playback::methods::check_labels(&spec.scenario, &spec.methods)
            .map_err(|e| anyhow!("{at}: {e}"))?;
    }
    Ok((spec, overrides))
}

/// Event frames in recorded frames: warm-up subtracted, events at one frame counted once.
pub(crate) fn event_frames(s: &sim::Scenario) -> Vec<u32> {
    let mut frames: Vec<u32> = s
        .events_summary()
        .into_iter()
        .filter_map(|(f, _)| f.checked_sub(s.warmup_frames))
        .filter(|&f| f < s.frames)
        .collect();
    frames.sort_unstable();
    frames.dedup();
    frames
}

/// Plays every case at every seed; run folders go to `FOLDER/CASE/seed_N`.
fn play(p: &Prepared, opts: &SuiteOptions) -> Result<BTreeMap<String, CaseRuns>> {
    let label = format!("suite {}", p.suite.name);
    play_cases(&p.suite.origin, &p.suite.cases, &p.folder, &opts.cache_dir, opts.progress, &label)
}

/// One case at one seed, checked: a scenario to play, or frames on disk already measured.
enum Planned {
    Play(Box<RunSpec>, Overrides),
    Measured(MeasureOptions, Box<Measured>),
}

/// Plays `cases` (read from `origin`) at each of their seeds into `FOLDER/CASE/seed_N`; every
/// case's input is checked (frames on disk read and measured) before the first one plays or
/// any run folder is written. `label` names the runs in the log.
pub(crate) fn play_cases(
    origin: &Path,
    cases: &[Case],
    folder: &Path,
    cache_dir: &Option<PathBuf>,
    progress: bool,
    label: &str,
) -> Result<BTreeMap<String, CaseRuns>> {
    let mut planned = Vec::new();
    for case in cases {
        for &seed in &case.seeds {
            let out = folder.join(&case.name).join(format!("seed_{seed}"));
            let plan = if let Some(frames) = &case.measure {
                let at = |e: anyhow::Error| anyhow!("{} seed {seed}: {e:#}", case_at(origin, case));
                let opts = frames.options(seed, &out).map_err(at)?;
                let measured = Measured::read(&opts).map_err(at)?;
                Planned::Measured(opts, Box::new(measured))
            } else {
                let (spec, overrides) = case_spec(origin, case, seed, &out)?;
                Planned::Play(Box::new(spec), overrides)
            };
            planned.push((case, seed, plan));
        }
    }
    let mut played: BTreeMap<String, CaseRuns> = BTreeMap::new();
    for (case, seed, plan) in planned {
        eprintln!("{label}: case {} seed {seed}", case.name);
        let runs = played.entry(case.name.clone()).or_default();
        let seed_run = match plan {
            Planned::Play(spec, overrides) => {
                let run_opts = RunOptions {
                    scenario: case.scenario.clone(),
                    overrides,
                    cache_dir: cache_dir.clone(),
                    progress,
                };
                // A signal keeps its type, so that the command exits as an interrupted run does.
                let summary = run_spec(&spec, &run_opts).map_err(|e| {
                    if e.is::<playback::interrupt::Interrupted>() {
                        e
                    } else {
                        anyhow!("case '{}' seed {seed}: {e:#}", case.name)
                    }
                })?;
                runs.frames = spec.scenario.frames;
                runs.events = event_frames(&spec.scenario);
                let mut seed_run = SeedRun::from_records(seed, &summary.records);
                seed_run.folder = Some(summary.folder.clone());
                seed_run
            }
            Planned::Measured(opts, measured) => {
                measured
                    .write(&opts)
                    .map_err(|e| anyhow!("case '{}' seed {seed}: {e:#}", case.name))?;
                runs.frames = measured.frames();
                let mut events: Vec<u32> =
                    opts.events.iter().map(|e| e - measured.first_frame()).collect();
                events.sort_unstable();
                events.dedup();
                runs.events = events;
                let mut seed_run = SeedRun::from_records(seed, measured.records());
                seed_run.folder = Some(opts.out.clone());
                seed_run
            }
        };
        runs.seeds.push(seed_run);
    }
    Ok(played)
}

fn bless_hint(p: &Prepared, opts: &SuiteOptions) -> String {
    format!(
        "record one with `flicker suite bless {}` on this adapter and commit {}",
        opts.suite.display(),
        p.baselines.display()
    )
}

/// `flicker suite run`: plays the suite and judges its gates; writes summary.md and junit.xml.
pub fn run(opts: &SuiteOptions) -> Result<SuiteOutcome> {
    let p = prepare(opts)?;
    let key = adapter_key(&p.adapter);
    let file = BaselineFile::load(&p.baselines)?;
    let chosen = file.for_adapter(&p.adapter);
    let baseline = chosen.map(|c| c.baseline);
    let relative = p.suite.gates.iter().any(|g| matches!(g.bound, Bound::Relative { .. }));
    if relative && baseline.is_none() {
        let known: Vec<&str> = file.adapters.keys().map(String::as_str).collect();
        bail!(
            "{}: no baseline for adapter '{key}' in {} (it has: {}); {}",
            opts.suite.display(),
            p.baselines.display(),
            if known.is_empty() { "none".to_string() } else { known.join(", ") },
            bless_hint(&p, opts)
        );
    }
    // No baseline of this adapter: another's stands in, every relative gate's tolerance widened
    // by the suite's other_adapter_tolerance, and the summary says so.
    let stand_in = chosen.filter(|c| relative && !c.exact).map(|c| {
        format!(
            "no baseline blessed on adapter '{key}'; compared with the baseline of '{}' (commit {}, blessed {}), every relative gate's tolerance widened by {} (other_adapter_tolerance); {}",
            c.key,
            c.baseline.commit,
            c.baseline.date,
            p.suite.other_adapter_tolerance,
            bless_hint(&p, opts)
        )
    });
    if let Some(note) = &stand_in {
        eprintln!("note: {note}");
    }
    let gates: Vec<Gate> = p
        .suite
        .gates
        .iter()
        .map(|g| match (&stand_in, &g.bound) {
            (Some(_), Bound::Relative { tolerance }) => Gate {
                bound: Bound::Relative { tolerance: tolerance + p.suite.other_adapter_tolerance },
                ..g.clone()
            },
            _ => g.clone(),
        })
        .collect();
    let cases = play(&p, opts)?;
    let mut results = Vec::new();
    for gate in &gates {
        for (name, runs) in &cases {
            for method in runs.methods().iter().filter(|m| gate.applies_to(name, m)) {
                results.push(judge(
                    gate,
                    name,
                    method,
                    runs,
                    baseline.and_then(|b| b.cases.get(name)),
                ));
            }
        }
    }
    // A gate that names a method no case ran would otherwise pass silently.
    for gate in &p.suite.gates {
        for method in gate.methods.iter().flatten() {
            if !cases.iter().any(|(name, runs)| {
                gate.applies_to(name, method) && runs.methods().contains(method)
            }) {
                let (line, _) = gate.entry.as_ref().map_or((1, 1), |e| (e.line, e.column));
                results.push(GateResult {
                    case: "-".into(),
                    method: method.clone(),
                    gate: gate.describe(),
                    new: None,
                    baseline: None,
                    p_value: None,
                    verdict: super::gate::Verdict::Error(format!(
                        "{}:{line}: no case ran method '{method}'",
                        opts.suite.display()
                    )),
                    detail: format!(
                        "{}:{line}: no case ran method '{method}'",
                        opts.suite.display()
                    ),
                });
            }
        }
    }
    let md = markdown::summary(
        &p.suite.name,
        &key,
        baseline.map(|b| (b.commit.as_str(), b.date.as_str())),
        stand_in.as_deref(),
        &results,
    );
    let summary = p.folder.join("summary.md");
    let junit_path = p.folder.join("junit.xml");
    frame::output::write_text(&summary, &md)?;
    frame::output::write_text(&junit_path, &junit::report(&p.suite.name, &results))?;
    Ok(SuiteOutcome { results, folder: p.folder, summary, junit: junit_path, markdown: md })
}

/// `flicker suite bless`: plays the suite and stores its measurements as this adapter's
/// baseline (other adapters' entries are kept). Returns the baseline file.
pub fn bless(opts: &SuiteOptions) -> Result<PathBuf> {
    let p = prepare(opts)?;
    // Read first: a damaged baseline file is reported before anything plays.
    let mut file = BaselineFile::load(&p.baselines)?;
    let mut cases = play(&p, opts)?;
    // JOD is one number per window, not per frame: the baseline keeps it for each JOD gate.
    for gate in p.suite.gates.iter().filter(|g| !g.metric.per_frame()) {
        for (name, runs) in cases.iter_mut() {
            let Some(range) = gate.window.frames(runs.frames, &runs.events) else { continue };
            for method in runs.methods().iter().filter(|m| gate.applies_to(name, m)) {
                for s in &mut runs.seeds {
                    s.keep_jod(method, &range);
                }
            }
        }
    }
    file.suite = p.suite.name.clone();
    let baseline = Baseline {
        commit: playback::manifest::commit(&opts.suite),
        date: now(),
        adapter: serde_json::to_value(&p.adapter)?,
        cases,
    };
    file.adapters.insert(adapter_key(&p.adapter), baseline);
    file.save(&p.baselines)?;
    Ok(p.baselines)
}
