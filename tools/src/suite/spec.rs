//! Suite files (RON): cases to play over seeds and gates their metrics must pass. Errors carry
//! the file, line and column, as scenario files' do (sim::scenario): `cases` and `gates` are
//! kept as raw entries with their place in the file and parsed one by one (`crate::ron_file`).

use std::collections::BTreeSet;
use std::path::{Path, PathBuf};

use serde::{Deserialize, Serialize};
use sim::scenario::{MethodEntry, ScenarioError};

use super::measured::MeasuredFrames;
use super::metric::Metric;
use super::window::Window;
use crate::ron_file::{self, RonFile};

/// One scenario played once per seed, or frames on disk measured (`measure`, suites only).
#[derive(Clone, Debug, PartialEq, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Case {
    pub name: String,
    /// Relative paths are resolved against the suite file's folder.
    #[serde(default)]
    pub scenario: PathBuf,
    /// Frames from another renderer instead of a scenario; without `seeds`, one run (seed 0).
    #[serde(default)]
    pub measure: Option<MeasuredFrames>,
    #[serde(default)]
    pub seeds: Vec<u64>,
    #[serde(default)]
    pub frames: Option<u32>,
    #[serde(default)]
    pub resolution: Option<(u32, u32)>,
    #[serde(default)]
    pub spp: Option<u32>,
    /// Only these method labels of the scenario (after `spp`); all when absent.
    #[serde(default)]
    pub methods: Option<Vec<String>>,
    /// Method parameters (label, field path, value) set after `methods`: a claims file's
    /// per-scale `set` (not read from suite files).
    #[serde(skip)]
    pub params: Vec<(String, Vec<String>, serde_json::Value)>,
    #[serde(skip)]
    pub entry: Option<MethodEntry>,
}

/// How a gate's per-seed values are judged.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub enum Bound {
    /// `Absolute(limit: 0.5)`: the mean over seeds must not be worse than `limit` (above it, or
    /// below it for PSNR).
    Absolute { limit: f64 },
    /// `Relative(tolerance: 0.05)`: fails when the new mean is worse than the baseline mean by more
    /// than `tolerance` times the baseline mean, with the gate's confidence (Welch's one-sided
    /// t-test).
    Relative { tolerance: f64 },
    /// `Better(than: "nirc_ema_1spp")`: a relation between methods of the same runs (a paper's
    /// claim). Passes only when the gate's method is better than `than` with the gate's
    /// confidence: the paired per-seed differences' one-sided Student t test, so the margin
    /// comes from the spread across seeds. Needs no baseline.
    Better { than: String },
}

fn default_confidence() -> f64 {
    0.95
}

#[derive(Clone, Debug, PartialEq, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Gate {
    pub metric: Metric,
    pub window: Window,
    pub bound: Bound,
    #[serde(default = "default_confidence")]
    pub confidence: f64,
    /// Only these cases / method labels; all when absent.
    #[serde(default)]
    pub cases: Option<Vec<String>>,
    #[serde(default)]
    pub methods: Option<Vec<String>>,
    #[serde(skip)]
    pub entry: Option<MethodEntry>,
}

impl Gate {
    /// A short name: `flip after_event_0(2) relative 10%`.
    pub fn describe(&self) -> String {
        let bound = match self.bound {
            Bound::Absolute { limit } => {
                format!("{} {limit}", if self.metric.higher_is_better() { ">=" } else { "<=" })
            }
            Bound::Relative { tolerance } => {
                format!("within {:.1}% of baseline", tolerance * 100.0)
            }
            Bound::Better { ref than } => format!("better than {than}"),
        };
        format!("{} {} {bound}", self.metric.name(), self.window.name())
    }

    pub fn applies_to(&self, case: &str, method: &str) -> bool {
        self.cases.as_ref().is_none_or(|c| c.iter().any(|n| n == case))
            && self.methods.as_ref().is_none_or(|m| m.iter().any(|n| n == method))
    }
}

#[derive(Deserialize)]
#[serde(rename = "Suite", deny_unknown_fields)]
struct SuiteFile {
    #[serde(default)]
    name: Option<String>,
    cases: Vec<Box<ron::value::RawValue>>,
    gates: Vec<Box<ron::value::RawValue>>,
    #[serde(default = "default_other_adapter_tolerance")]
    other_adapter_tolerance: f64,
}

/// What relative gates add to their tolerance when the baseline was blessed on another adapter.
/// An argued threshold, not a measured one: the same seeds give the same noise only where two
/// drivers round alike, and the Welch test's spread over seeds covers decorrelated noise; the
/// margin covers what that spread cannot, systematic differences of a few percent in shader
/// arithmetic (WGSL lets transcendental functions and FMA contraction differ by driver).
pub const DEFAULT_OTHER_ADAPTER_TOLERANCE: f64 = 0.05;

fn default_other_adapter_tolerance() -> f64 {
    DEFAULT_OTHER_ADAPTER_TOLERANCE
}

#[derive(Clone, Debug)]
pub struct Suite {
    /// Defaults to the file's stem; names the baseline file.
    pub name: String,
    pub cases: Vec<Case>,
    pub gates: Vec<Gate>,
    /// Added to relative gates' tolerance when the baseline is a stand-in blessed on another
    /// adapter (`suite::baseline::BaselineFile::for_adapter`).
    pub other_adapter_tolerance: f64,
    pub origin: PathBuf,
}

/// The `cases` of a suite or sweep file: each parsed at its place in the file, seeds checked,
/// names distinct, scenario paths resolved against the file's folder. Cases over frames on disk
/// (`measure`) only where `measured` (suites: a sweep varies what is rendered).
pub(crate) fn parse_cases(
    file: RonFile,
    raw: &[Box<ron::value::RawValue>],
    measured: bool,
) -> Result<Vec<Case>, ScenarioError> {
    let folder = file.origin.parent().unwrap_or(Path::new(""));
    let mut cases: Vec<Case> = Vec::new();
    for entry in file.entries("cases", raw) {
        let mut case: Case = file.entry(&entry)?;
        if let Some(problem) = measured_case(&mut case, measured, folder) {
            return Err(file.error_at(&entry, format!("case '{}': {problem}", case.name)));
        }
        if case.seeds.is_empty() {
            return Err(file.error_at(
                &entry,
                format!("case '{}' has no seeds; expected e.g. seeds: [1, 2, 3]", case.name),
            ));
        }
        if let Some(dup) = case.seeds.iter().enumerate().find(|(i, s)| case.seeds[..*i].contains(s))
        {
            return Err(file.error_at(
                &entry,
                format!("case '{}' lists seed {} twice; expected distinct seeds", case.name, dup.1),
            ));
        }
        if cases.iter().any(|c| c.name == case.name) {
            return Err(file.error_at(
                &entry,
                format!(
                    "two cases are named '{}'; expected distinct names (they name run folders and baselines)",
                    case.name
                ),
            ));
        }
        if case.measure.is_none() && case.scenario.is_relative() {
            case.scenario = folder.join(&case.scenario);
        }
        case.entry = Some(entry);
        cases.push(case);
    }
    if cases.is_empty() {
        return Err(file.error(None, "no cases; expected e.g. cases: [(name: \"cornell\", scenario: \"scenarios/cornell_box.ron\", seeds: [1, 2])]".into()));
    }
    Ok(cases)
}

/// Checks a case's choice between a scenario and frames on disk; a measured case gets seed 0
/// when it has no seeds and its folders resolved against `folder`.
fn measured_case(case: &mut Case, allowed: bool, folder: &Path) -> Option<String> {
    let scenario = !case.scenario.as_os_str().is_empty();
    let Some(m) = &mut case.measure else {
        return (!scenario).then(|| {
            let frames =
                if allowed { " or measure: (reference: DIR, tests: {NAME: DIR})" } else { "" };
            format!("no scenario; expected scenario: \"scenarios/NAME.ron\"{frames}")
        });
    };
    if !allowed {
        return Some(
            "measure: frames on disk are a suite's; expected scenario: \"scenarios/NAME.ron\""
                .into(),
        );
    }
    if scenario {
        return Some("names a scenario and measure; expected one of them".into());
    }
    let rendering = [
        ("frames", case.frames.is_some()),
        ("resolution", case.resolution.is_some()),
        ("spp", case.spp.is_some()),
        ("methods", case.methods.is_some()),
    ];
    if let Some((field, _)) = rendering.iter().find(|f| f.1) {
        return Some(format!(
            "{field} sets how a scenario is played; a measured case's frames are its folders' (leave {field} out)"
        ));
    }
    let seeded = !case.seeds.is_empty();
    if let Some(problem) = m.problem(seeded) {
        return Some(problem);
    }
    m.resolve(folder);
    if !seeded {
        case.seeds = vec![0];
    }
    None
}

impl Suite {
    pub fn load(path: &Path) -> Result<Suite, ScenarioError> {
        Self::from_ron(&ron_file::read(path, "suite file")?, path)
    }

    pub fn from_ron(text: &str, origin: &Path) -> Result<Suite, ScenarioError> {
        let file = RonFile { text, origin };
        let parsed: SuiteFile = file.parse()?;
        let cases = parse_cases(file, &parsed.cases, true)?;
        let names: BTreeSet<&str> = cases.iter().map(|c| c.name.as_str()).collect();
        let mut gates = Vec::new();
        for entry in file.entries("gates", &parsed.gates) {
            let mut gate: Gate = file.entry(&entry)?;
            if !(gate.confidence > 0.5 && gate.confidence < 1.0) {
                return Err(file.error_at(
                    &entry,
                    format!(
                        "confidence {}; expected a probability between 0.5 and 1, e.g. 0.95",
                        gate.confidence
                    ),
                ));
            }
            if gate.metric.from_images() {
                return Err(file.error_at(
                    &entry,
                    format!(
                        "metric {} is computed by `flicker reproduce` against a claim's `against` method; expected a metric of frames.csv",
                        gate.metric.name()
                    ),
                ));
            }
            if let Some(playback::methods::FolderInput::EventAndMap { map, .. }) =
                gate.metric.from_images_by().map(|i| i.input)
            {
                return Err(file.error_at(
                    &entry,
                    format!(
                        "metric {} is computed by `flicker reproduce` from a run's {map} maps; expected a metric of frames.csv, e.g. BlendSigma",
                        gate.metric.name()
                    ),
                ));
            }
            if gate.metric == Metric::PassMs {
                return Err(file.error_at(
                    &entry,
                    "metric pass_ms is summed by `flicker reproduce` over a claim's passes; expected a metric of frames.csv, e.g. FrameMs".into(),
                ));
            }
            if gate.metric.reproduce_only() {
                return Err(file.error_at(
                    &entry,
                    format!("metric {} is read by `flicker reproduce` only; expected a metric a suite keeps, e.g. PathLength", gate.metric.name()),
                ));
            }
            match gate.bound {
                Bound::Relative { tolerance: t } if !(t.is_finite() && t >= 0.0) => {
                    return Err(file.error_at(
                        &entry,
                        format!("tolerance {t}; expected a fraction >= 0, e.g. 0.05 for 5%"),
                    ));
                }
                Bound::Absolute { limit: l } if !l.is_finite() => {
                    return Err(
                        file.error_at(&entry, format!("limit {l}; expected a finite number"))
                    );
                }
                _ => {}
            }
            if let Some(why) = gate.window.empty() {
                return Err(file.error_at(&entry, format!("window {}: {why}", gate.window.name())));
            }
            if let Some(unknown) = gate.cases.iter().flatten().find(|c| !names.contains(c.as_str()))
            {
                return Err(file.error_at(
                    &entry,
                    format!(
                        "gate names case '{unknown}'; the suite's cases are: {}",
                        names.iter().copied().collect::<Vec<_>>().join(", ")
                    ),
                ));
            }
            if matches!(gate.bound, Bound::Relative { .. } | Bound::Better { .. })
                && let Some(case) = cases.iter().find(|c| {
                    c.seeds.len() < 2 && gate.cases.as_ref().is_none_or(|g| g.contains(&c.name))
                })
            {
                let kind = if matches!(gate.bound, Bound::Better { .. }) {
                    "relation"
                } else {
                    "relative"
                };
                return Err(file.error_at(
                    &entry,
                    format!(
                        "a {kind} gate needs the spread over seeds, but case '{}' has one seed; expected at least 2",
                        case.name
                    ),
                ));
            }
            gate.entry = Some(entry);
            gates.push(gate);
        }
        if gates.is_empty() {
            return Err(file.error(None, "no gates; expected e.g. gates: [(metric: Flip, window: Overall, bound: Relative(tolerance: 0.05))]".into()));
        }
        let t = parsed.other_adapter_tolerance;
        if !(t.is_finite() && t >= 0.0) {
            return Err(file.error(
                file.text.find("other_adapter_tolerance").map(|at| sim::scenario::line_col(text, at)),
                format!(
                    "other_adapter_tolerance {t}; expected a fraction >= 0, e.g. {DEFAULT_OTHER_ADAPTER_TOLERANCE}"
                ),
            ));
        }
        let name = file.name_or_stem(parsed.name, "suite");
        Ok(Suite { name, cases, gates, other_adapter_tolerance: t, origin: origin.to_path_buf() })
    }

    /// Where baselines of this suite live: `baselines/NAME.json` next to the suite file.
    pub fn baseline_file(&self) -> PathBuf {
        self.origin
            .parent()
            .unwrap_or(Path::new(""))
            .join("baselines")
            .join(format!("{}.json", self.name))
    }
}
