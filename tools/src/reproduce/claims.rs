//! Claims files (RON, `claims/PAPER.ron`): a paper's headline claims as data. Each names where
//! the paper makes it, the paper's numbers, the case (scenario and methods) that tests it here,
//! the statistic (a suite metric over a window), the comparison, the smallest effect that
//! matters and where it comes from, and the known departures. Everything is checked before anything plays: an unknown
//! case, a missing scenario, a method the case does not run, a statistic the method does not
//! record and a window on an event the case's scenario lacks at some scale (`events`) are errors
//! at the claim's file:line.

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

use playback::play::{Overrides, RunSpec};
use serde::Deserialize;
use sim::scenario::{MethodEntry, ReferenceFrames, ScenarioError};

use crate::ron_file::{self, RonFile};
use playback::methods::{FolderInput, Source};

use crate::suite::metric::Metric;
use crate::suite::spec::Case;
use crate::suite::window::Window;

use super::by_window::ByWindow;
use super::case_methods::CaseMethods;
use super::computation::Computation;
use super::effect::Effect;
use super::events::CaseEvents;
use super::log_ratio::RatioExpectation;

/// How big a reproduction runs: `Smoke` (tiny: about two minutes a paper on 2 cores), `Lab`
/// (the scenarios as shipped) or `Paper` (the paper's sizes where the file gives them).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Scale {
    Smoke,
    Lab,
    Paper,
}

impl Scale {
    pub fn parse(s: &str) -> Result<Scale, String> {
        match s {
            "smoke" => Ok(Scale::Smoke),
            "lab" => Ok(Scale::Lab),
            "paper" => Ok(Scale::Paper),
            _ => Err(format!("scale '{s}'; expected smoke, lab or paper")),
        }
    }

    pub fn name(self) -> &'static str {
        match self {
            Scale::Smoke => "smoke",
            Scale::Lab => "lab",
            Scale::Paper => "paper",
        }
    }
}

/// Overrides of a case at one scale; absent fields keep the scenario's.
#[derive(Clone, Debug, Default, PartialEq, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Size {
    #[serde(default)]
    pub frames: Option<u32>,
    #[serde(default)]
    pub resolution: Option<(u32, u32)>,
    #[serde(default)]
    pub spp: Option<u32>,
    /// Seeds at this scale: the case's first `seeds` (`--seeds` still overrides).
    #[serde(default)]
    pub seeds: Option<usize>,
    /// Method parameters at this scale (what a smaller image alone does not shrink, such as
    /// NIRC's pre-training): `("nirc_ema_1spp.pretrain_frames", 8)` sets one method's, as a
    /// sweep's parameter; `("Nirc.pretrain_frames", 8)` every method of that kind. Kinds are
    /// expanded to labels when the file is loaded. A parameter may not change a label.
    #[serde(default)]
    pub set: Vec<(String, serde_json::Value)>,
    /// `set` per method: (label, field path, value), filled when the file is loaded.
    #[serde(skip)]
    pub params: Vec<(String, Vec<String>, serde_json::Value)>,
}

/// A scenario the claims play, at each scale, or a computation (a paper's closed form or CPU
/// Monte Carlo test case); exactly one of the two.
#[derive(Clone, Debug, PartialEq, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ClaimCase {
    pub name: String,
    /// Relative paths are resolved against the claims file's folder.
    #[serde(default)]
    pub scenario: Option<PathBuf>,
    #[serde(default)]
    pub computation: Option<Computation>,
    pub seeds: Vec<u64>,
    /// Only these method labels of the scenario; all when absent.
    #[serde(default)]
    pub methods: Option<Vec<String>>,
    /// Statistics shown in the case's table beside its claims' (a paper table's other
    /// columns, such as Table 1's per-pass times): no `against` or `not_run`.
    #[serde(default)]
    pub table: Vec<Statistic>,
    /// Metrics over several windows, a table per metric (`reproduce::by_window`).
    #[serde(default)]
    pub by_window: Option<ByWindow>,
    #[serde(default)]
    pub smoke: Size,
    #[serde(default)]
    pub lab: Size,
    #[serde(default)]
    pub paper: Size,
}

/// The number a claim reads from each seed's run: `metric`'s mean over `window`.
#[derive(Clone, Debug, PartialEq, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Statistic {
    pub metric: Metric,
    pub window: Window,
    /// The method of the case whose frames are the reference of a metric computed from images
    /// (`SssPsnr`: the converged pass); only for those, and one per case.
    #[serde(default)]
    pub against: Option<String>,
    /// `FrameMs` only: per method label, passes of a cache it shares with other methods of the
    /// run that it would not run alone, left out of its time (`reproduce::alone`): a paper that
    /// times each method in its own run charges it only what it runs. One list per case.
    #[serde(default)]
    pub not_run: Vec<(String, Vec<String>)>,
    /// `PassMs` only: the passes whose ms it sums (`reproduce::pass_ms`), e.g. `["tc_trace"]`.
    #[serde(default)]
    pub passes: Vec<String>,
}

impl Statistic {
    pub fn describe(&self) -> String {
        let mut name = self.metric.name().to_string();
        if let Some(a) = &self.against {
            name.push_str(&format!(" vs {a}"));
        }
        if !self.passes.is_empty() {
            name.push_str(&format!(" ({})", self.passes.join(" + ")));
        }
        for (m, passes) in &self.not_run {
            name.push_str(&format!(" ({m} without {})", passes.join(", ")));
        }
        format!("{name} {}", self.window.name())
    }

    /// The key of its series in a seed run's metrics: the metric's name, with `PassMs`'s
    /// passes (one series per set of passes).
    pub fn key(&self) -> String {
        match self.metric {
            Metric::PassMs => super::pass_ms::key(&self.passes),
            m => m.name().to_string(),
        }
    }
}

fn default_confidence() -> f64 {
    0.95
}

/// What the paper's claim says about the statistic.
#[derive(Clone, Debug, PartialEq, Deserialize)]
#[serde(deny_unknown_fields)]
pub enum Comparison {
    /// `Below(method: "a", than: "b")`: a's statistic is lower than b's in the same runs, by
    /// at least the claim's smallest effect, judged on the paired per-seed differences.
    Below {
        method: String,
        than: String,
        #[serde(default = "default_confidence")]
        confidence: f64,
    },
    /// `NotAbove(method: "a", than: "b")`: a's statistic is not above b's by the claim's
    /// smallest effect or more (the paper's "no worse than"), on the paired differences.
    NotAbove {
        method: String,
        than: String,
        #[serde(default = "default_confidence")]
        confidence: f64,
    },
    /// `Value(method: "a", value: 0.3)`: a's mean is the paper's value, within the claim's
    /// smallest effect.
    Value {
        method: String,
        value: f64,
        #[serde(default = "default_confidence")]
        confidence: f64,
    },
    /// `Ratio(method: "a", to: "b", value: 0.5)`: the per-seed ratio a / b is the paper's
    /// value, within the claim's smallest effect.
    Ratio {
        method: String,
        to: String,
        value: f64,
        #[serde(default = "default_confidence")]
        confidence: f64,
    },
    /// `Difference(method: "a", to: "b", value: 0.3)`: the per-seed difference a − b is the
    /// paper's value, within the claim's smallest effect (for a logarithmic statistic such as
    /// PSNR in dB, where a ratio of values means nothing).
    Difference {
        method: String,
        to: String,
        value: f64,
        #[serde(default = "default_confidence")]
        confidence: f64,
    },
    /// `LogRatio(method: "a", to: "b", expect: Below(1.0))` or `expect: Near(3.0)`: the
    /// per-seed ratio a / b of the same runs, judged in the log (`reproduce::log_ratio`): for
    /// claims about factors of a bias, a std or an error.
    LogRatio {
        method: String,
        to: String,
        expect: RatioExpectation,
        #[serde(default = "default_confidence")]
        confidence: f64,
    },
    /// `Rises(method: "a", from: Before(event: 0))`: a's statistic over the claim's window is
    /// higher than over `from`, judged as the paired per-seed differences of `Below`.
    Rises {
        method: String,
        from: Window,
        #[serde(default = "default_confidence")]
        confidence: f64,
    },
    /// The lab does not record what the claim needs (yet); `methods` are still checked.
    NotComparable {
        #[serde(default)]
        methods: Vec<String>,
        reason: String,
    },
}

impl Comparison {
    pub fn methods(&self) -> Vec<&str> {
        match self {
            Comparison::Below { method, than, .. } | Comparison::NotAbove { method, than, .. } => {
                vec![method, than]
            }
            Comparison::Value { method, .. } | Comparison::Rises { method, .. } => vec![method],
            Comparison::Ratio { method, to, .. }
            | Comparison::Difference { method, to, .. }
            | Comparison::LogRatio { method, to, .. } => vec![method, to],
            Comparison::NotComparable { methods, .. } => {
                methods.iter().map(|m| m.as_str()).collect()
            }
        }
    }

    pub fn describe(&self) -> String {
        match self {
            Comparison::Below { method, than, .. } => format!("{method} below {than}"),
            Comparison::NotAbove { method, than, .. } => format!("{method} not above {than}"),
            Comparison::Value { method, value, .. } => format!("{method} = {value}"),
            Comparison::Ratio { method, to, value, .. } => format!("{method} / {to} = {value}"),
            Comparison::Difference { method, to, value, .. } => {
                format!("{method} − {to} = {value}")
            }
            Comparison::LogRatio { method, to, expect, .. } => {
                format!("{method} / {to} {} (log ratio)", expect.describe())
            }
            Comparison::Rises { method, from, .. } => {
                format!("{method} rises from {}", from.name())
            }
            Comparison::NotComparable { .. } => "not comparable".into(),
        }
    }
}

/// One headline claim of the paper.
#[derive(Clone, Debug, PartialEq, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Claim {
    /// Short and unique in the file.
    pub id: String,
    /// The claim in a sentence.
    pub claim: String,
    /// Where the paper makes it: "Table 1", "Section 4, Figure 5".
    pub source: String,
    /// The paper's number(s) and their conditions, as the paper states them.
    pub paper: String,
    /// The case that tests it; may be absent only for `NotComparable`.
    #[serde(default)]
    pub case: Option<String>,
    #[serde(default)]
    pub statistic: Option<Statistic>,
    pub comparison: Comparison,
    /// The smallest effect that matters: a relation's smallest difference (or factor) worth
    /// the name, a value's largest departure from the paper's number that still agrees.
    pub smallest_effect: Effect,
    /// Where it comes from: the paper (its ± or its stated precision) or an argued perceptual
    /// or practical threshold (a FLIP step, a JOD step, a share of frame time); never from the
    /// lab's own runs of the claim.
    pub smallest_effect_from: String,
    #[serde(default)]
    pub departures: Vec<String>,
    /// This claim is another claim of the file judged again with one condition switched (a
    /// departure of ours turned on or off): the report sets the two verdicts side by side, so
    /// a reader sees which condition a failure comes from.
    #[serde(default)]
    pub variant_of: Option<VariantOf>,
    /// The claim's line in its file (filled when loaded).
    #[serde(skip)]
    pub line: usize,
}

/// `variant_of: Some((claim: "cv_fewer_samples", switched: "irradiance: PathTraced"))`.
#[derive(Clone, Debug, PartialEq, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct VariantOf {
    /// The claim judged under the other condition; defined in the same file, itself no variant.
    pub claim: String,
    /// What differs from that claim's condition, in a phrase.
    pub switched: String,
}

#[derive(Deserialize)]
#[serde(rename = "Claims", deny_unknown_fields)]
struct ClaimsFile {
    /// The seed paper's stem: `/work/shared/seeds/PAPER.txt`, `claims/PAPER.ron`.
    paper: String,
    title: String,
    cases: Vec<Box<ron::value::RawValue>>,
    claims: Vec<Box<ron::value::RawValue>>,
}

#[derive(Clone, Debug)]
pub struct Claims {
    pub paper: String,
    pub title: String,
    pub cases: Vec<ClaimCase>,
    pub claims: Vec<Claim>,
    pub origin: PathBuf,
    /// Each case's line in the file.
    pub case_lines: BTreeMap<String, (usize, usize)>,
}

/// `set` as (label, field path, value), a `Kind.field` parameter once per method of that kind;
/// each applied to a copy of `methods` so that a wrong field or value, or a changed label, is
/// an error here. Labels may hold dots (`vb_0.01`): the longest label followed by a dot wins.
fn expand_set(
    methods: &[playback::methods::Method],
    set: &[(String, serde_json::Value)],
) -> Result<Vec<(String, Vec<String>, serde_json::Value)>, String> {
    let mut out: Vec<(String, Vec<String>, serde_json::Value)> = Vec::new();
    let fields = |rest: &str| -> Vec<String> { rest.split('.').map(str::to_string).collect() };
    for (param, value) in set {
        let by_label = methods
            .iter()
            .map(|m| m.label())
            .filter(|l| param.len() > l.len() + 1 && param.starts_with(&format!("{l}.")))
            .max_by_key(|l| l.len());
        let targets: Vec<(String, Vec<String>)> = match by_label {
            Some(l) => vec![(l.clone(), fields(&param[l.len() + 1..]))],
            None => {
                let (kind, rest) = param.split_once('.').unwrap_or((param, ""));
                methods
                    .iter()
                    .filter(|m| m.spec.name() == kind && !rest.is_empty())
                    .map(|m| (m.label(), fields(rest)))
                    .collect()
            }
        };
        if targets.is_empty() {
            return Err(format!(
                "parameter '{param}'; expected METHOD_LABEL.field or Kind.field of the case's methods: {}",
                methods
                    .iter()
                    .map(|m| format!("{} ({})", m.label(), m.spec.name()))
                    .collect::<Vec<_>>()
                    .join(", ")
            ));
        }
        for (label, path) in targets {
            if out.iter().any(|(l, p, _)| *l == label && *p == path) {
                return Err(format!("'{label}.{}' is set twice", path.join(".")));
            }
            out.push((label, path, value.clone()));
        }
    }
    let mut check = methods.to_vec();
    crate::sweep::param::set_each(&mut check, &out)?;
    // Claims name methods by label, the same at every scale.
    let before: Vec<String> = methods.iter().map(|m| m.label()).collect();
    let after: Vec<String> = check.iter().map(|m| m.label()).collect();
    if before != after {
        return Err(format!(
            "the parameters change labels ({} become {}); expected parameters that keep them",
            before.join(", "),
            after.join(", ")
        ));
    }
    Ok(out)
}

/// A metric computed from images names a reference method (`against`) of the case, of the
/// metric's kind, the same for every claim on the case; other metrics name none.
fn check_against(
    s: &Statistic,
    case: &CaseMethods,
    name: &str,
    seen: &mut BTreeMap<String, String>,
) -> Result<(), String> {
    let metric = s.metric.name();
    let Some(a) = &s.against else {
        return if s.metric.from_images() {
            Err(format!(
                "the statistic {metric} needs a reference method; expected e.g. against: \"pass_2048\""
            ))
        } else {
            Ok(())
        };
    };
    if !s.metric.from_images() {
        return Err(format!(
            "against: \"{a}\" with the statistic {metric}, which is read from frames.csv; expected no against"
        ));
    }
    let Some(kind) = case.kinds.get(a) else {
        return Err(format!(
            "against: no method '{a}' in case '{name}'; its methods are: {}",
            case.kinds.keys().cloned().collect::<Vec<_>>().join(", ")
        ));
    };
    if !s.metric.recorded_by(kind, case.references) {
        return Err(format!("against: '{a}' ({kind}) has no images {metric} can be measured on"));
    }
    match seen.get(name) {
        Some(other) if other != a => Err(format!(
            "against: '{a}', but another claim on case '{name}' measures {metric} against '{other}'; expected one reference per case"
        )),
        _ => {
            seen.insert(name.to_string(), a.clone());
            Ok(())
        }
    }
}

/// `not_run` only with `FrameMs`, on methods of the case, and the same for every `FrameMs`
/// claim on the case (one time per method and frame).
fn check_not_run(
    s: &Statistic,
    case: &CaseMethods,
    name: &str,
    seen: &mut BTreeMap<String, Vec<(String, Vec<String>)>>,
) -> Result<(), String> {
    if s.metric != Metric::FrameMs {
        return match s.not_run.first() {
            Some(_) => Err(format!(
                "not_run with the statistic {}; expected it only with FrameMs",
                s.metric.name()
            )),
            None => Ok(()),
        };
    }
    if let Some((m, _)) = s.not_run.iter().find(|(m, _)| !case.kinds.contains_key(m)) {
        return Err(format!(
            "not_run: no method '{m}' in case '{name}'; its methods are: {}",
            case.kinds.keys().cloned().collect::<Vec<_>>().join(", ")
        ));
    }
    if case.computed.is_some() && !s.not_run.is_empty() {
        return Err("not_run on a computed case, which has no passes".into());
    }
    match seen.get(name) {
        Some(other) if *other != s.not_run => Err(format!(
            "not_run differs from another FrameMs claim's on case '{name}'; expected one attribution per case"
        )),
        _ => {
            seen.insert(name.to_string(), s.not_run.clone());
            Ok(())
        }
    }
}

/// `passes` with `PassMs` only, and there at least one, each named once.
fn check_passes(s: &Statistic, case: &CaseMethods) -> Result<(), String> {
    let metric = s.metric.name();
    match (s.metric == Metric::PassMs, s.passes.is_empty()) {
        (true, true) => {
            return Err(format!("{metric} without passes; expected e.g. passes: [\"tc_trace\"]"));
        }
        (false, false) => {
            return Err(format!(
                "passes with the statistic {metric}; expected them only with PassMs"
            ));
        }
        _ => {}
    }
    if case.computed.is_some() && !s.passes.is_empty() {
        return Err("passes on a computed case, which has no passes".into());
    }
    for (i, p) in s.passes.iter().enumerate() {
        if p.is_empty() || p.contains(',') || s.passes[..i].contains(p) {
            return Err(format!("pass '{p}'; expected distinct pass names"));
        }
    }
    Ok(())
}

fn check_confidence(file: RonFile, line: usize, c: f64) -> Result<(), ScenarioError> {
    if c > 0.5 && c < 1.0 {
        Ok(())
    } else {
        Err(file.error(
            Some((line, 1)),
            format!("confidence {c}; expected a probability between 0.5 and 1, e.g. 0.95"),
        ))
    }
}

/// One entry of `cases`, checked (`cases`: the entries before it): the case, the methods of its
/// scenario or its computation, and its events.
fn read_case(
    file: RonFile,
    entry: &MethodEntry,
    folder: &Path,
    cases: &[ClaimCase],
) -> Result<(ClaimCase, CaseMethods, CaseEvents), ScenarioError> {
    let mut case: ClaimCase = file.entry(entry)?;
    if case.seeds.is_empty() {
        return Err(file.error_at(
            entry,
            format!("case '{}' has no seeds; expected e.g. seeds: [1, 2, 3]", case.name),
        ));
    }
    if cases.iter().any(|c| c.name == case.name) {
        return Err(file.error_at(
            entry,
            format!("two cases are named '{}'; expected distinct names", case.name),
        ));
    }
    let at = |m: String| file.error_at(entry, format!("case '{}': {m}", case.name));
    let scenario_path = match (&mut case.scenario, &case.computation) {
        (Some(p), None) => {
            if p.is_relative() {
                *p = folder.join(&*p);
            }
            p.clone()
        }
        (None, Some(c)) => {
            let computed = c.methods().map_err(|e| at(format!("{}: {e}", c.name())))?;
            let kinds = computed.keys().map(|l| (l.clone(), c.name())).collect();
            if !case.table.is_empty() {
                return Err(at("table: a computed case's table holds its claims' statistics only; expected no table".into()));
            }
            if case.methods.is_some() {
                return Err(at(
                    "methods: a computed case has no scenario to choose from; expected no methods"
                        .into(),
                ));
            }
            if case.by_window.is_some() {
                return Err(at(
                    "by_window: a computed case has no frames; expected no by_window".into()
                ));
            }
            let references = false;
            let methods = CaseMethods {
                kinds,
                references,
                computed: Some(computed),
                image_maps: BTreeMap::new(),
            };
            return Ok((case, methods, CaseEvents::default()));
        }
        _ => {
            return Err(at(
                "expected either scenario: \"PATH.ron\" or computation: ... (not both)".into(),
            ));
        }
    };
    let (case_methods, case_events) = scenario_case(file, entry, &mut case, &scenario_path)?;
    Ok((case, case_methods, case_events))
}

/// A case that plays `scenario_path`: its methods (those it keeps) and events, its scales' sets
/// expanded, its table and `by_window` checked against them.
fn scenario_case(
    file: RonFile,
    entry: &MethodEntry,
    case: &mut ClaimCase,
    scenario_path: &Path,
) -> Result<(CaseMethods, CaseEvents), ScenarioError> {
    let at = |m: String| file.error_at(entry, format!("case '{}': {m}", case.name));
    if !scenario_path.is_file() {
        return Err(at(format!("scenario {} does not exist", scenario_path.display())));
    }
    let scenario = sim::Scenario::load(scenario_path).map_err(|e| at(e.to_string()))?;
    let spec = RunSpec::from_scenario(scenario, &Overrides::default())
        .map_err(|e| at(format!("{e:#}")))?;
    let mut kinds: BTreeMap<String, &'static str> =
        spec.methods.iter().map(|m| (m.label(), m.spec.name())).collect();
    if let Some(keep) = &case.methods {
        if let Some(unknown) = keep.iter().find(|k| !kinds.contains_key(*k)) {
            return Err(at(format!(
                "no method labelled '{unknown}' in {}; its methods are: {}",
                scenario_path.display(),
                kinds.keys().cloned().collect::<Vec<_>>().join(", ")
            )));
        }
        kinds.retain(|label, _| keep.contains(label));
    }
    let mut played = spec.methods.clone();
    if let Some(keep) = &case.methods {
        played.retain(|m| keep.contains(&m.label()));
    }
    let name = case.name.clone();
    for (scale, size) in
        [("smoke", &mut case.smoke), ("lab", &mut case.lab), ("paper", &mut case.paper)]
    {
        let at = |m: String| file.error_at(entry, format!("case '{name}': {scale}: {m}"));
        if size.seeds.is_some_and(|n| n < 2) {
            return Err(at("seeds below 2; an interval needs at least 2".into()));
        }
        size.params = expand_set(&played, &size.set).map_err(at)?;
    }
    let case_events = CaseEvents::of(
        &spec.scenario,
        [("smoke", case.smoke.frames), ("lab", case.lab.frames), ("paper", case.paper.frames)],
    );
    let r = &spec.scenario.reference;
    let references = r.spp > 0 && r.frames != ReferenceFrames::None;
    let image_maps = playback::methods::registry::statistics()
        .into_iter()
        .filter_map(|s| match s.source {
            Source::Images(i) => match i.input {
                FolderInput::EventAndMap { map, .. } => Some(map),
                _ => None,
            },
            _ => None,
        })
        .map(|map| {
            let writers = played.iter().filter(|m| m.spec.writes_image(map));
            (map, writers.map(|m| m.label()).collect())
        })
        .collect();
    let case_methods = CaseMethods { kinds, references, computed: None, image_maps };
    for s in &case.table {
        let at = |m: String| at(format!("table: {}: {m}", s.describe()));
        if s.against.is_some() || !s.not_run.is_empty() {
            return Err(at("against or not_run; expected them in a claim's statistic".into()));
        }
        check_passes(s, &case_methods).map_err(at)?;
        case_events.check(&s.window, &name).map_err(at)?;
    }
    if let Some(by) = &case.by_window {
        by.check(&case_methods).map_err(at)?;
        for w in &by.windows {
            case_events.check(w, &name).map_err(|m| at(format!("by_window: {m}")))?;
        }
    }
    Ok((case_methods, case_events))
}

/// One entry of `claims`, checked against the file's cases and the claims before it; `against`
/// and `not_run` gather, per case, what its claims' statistics must agree on.
fn read_claim(
    file: RonFile,
    entry: &MethodEntry,
    claims: &[Claim],
    methods: &BTreeMap<String, CaseMethods>,
    events: &BTreeMap<String, CaseEvents>,
    against: &mut BTreeMap<String, String>,
    not_run: &mut BTreeMap<String, Vec<(String, Vec<String>)>>,
) -> Result<Claim, ScenarioError> {
    let mut claim: Claim = file.entry(entry)?;
    claim.line = entry.line;
    let at = |m: String| file.error_at(entry, format!("claim '{}': {m}", claim.id));
    if claims.iter().any(|c| c.id == claim.id) {
        return Err(at("the id is used twice; expected distinct ids".into()));
    }
    claim.smallest_effect.check().map_err(at)?;
    if claim.smallest_effect_from.trim().is_empty() {
        return Err(at("smallest_effect_from is empty; expected where the margin comes from: the paper or an argued threshold".into()));
    }
    match &claim.comparison {
        Comparison::Below { confidence, .. }
        | Comparison::NotAbove { confidence, .. }
        | Comparison::Rises { confidence, .. } => check_confidence(file, entry.line, *confidence)?,
        Comparison::Value { confidence, .. }
        | Comparison::Ratio { confidence, .. }
        | Comparison::Difference { confidence, .. } => {
            check_confidence(file, entry.line, *confidence)?;
        }
        Comparison::LogRatio { confidence, expect, .. } => {
            check_confidence(file, entry.line, *confidence)?;
            expect.check(&claim.smallest_effect).map_err(at)?;
            if let Some(s) = &claim.statistic {
                super::log_ratio::check_metric(s.metric).map_err(at)?;
            }
        }
        Comparison::NotComparable { .. } => {}
    }
    let comparable = !matches!(claim.comparison, Comparison::NotComparable { .. });
    let case = match &claim.case {
        Some(name) => Some(methods.get(name).ok_or_else(|| {
            at(format!(
                "no case '{name}'; the file's cases are: {}",
                methods.keys().cloned().collect::<Vec<_>>().join(", ")
            ))
        })?),
        None if comparable => {
            return Err(at("no case; expected e.g. case: \"cornell\"".into()));
        }
        None => None,
    };
    if comparable && claim.statistic.is_none() {
        return Err(at(
            "no statistic; expected e.g. statistic: (metric: Flip, window: Overall)".into()
        ));
    }
    if let (Some(case), Some(s)) = (case, &claim.statistic) {
        let name = claim.case.as_deref().unwrap_or_default();
        check_against(s, case, name, against).map_err(at)?;
        check_not_run(s, case, name, not_run).map_err(at)?;
        check_passes(s, case).map_err(at)?;
        let events = &events[name];
        events.check(&s.window, name).map_err(at)?;
        if let Comparison::Rises { from, .. } = &claim.comparison {
            events.check(from, name).map_err(|m| at(format!("from: {m}")))?;
        }
    }
    if let Some(case) = case {
        check_claim_methods(&claim, case, at)?;
    }
    Ok(claim)
}

/// Each method a claim compares is in its case and records the claim's statistic.
fn check_claim_methods(
    claim: &Claim,
    case: &CaseMethods,
    at: impl Fn(String) -> ScenarioError,
) -> Result<(), ScenarioError> {
    for m in claim.comparison.methods() {
        let Some(kind) = case.kinds.get(m) else {
            return Err(at(format!(
                "unknown method '{m}' in case '{}'; its methods are: {}",
                claim.case.as_deref().unwrap_or_default(),
                case.kinds.keys().cloned().collect::<Vec<_>>().join(", ")
            )));
        };
        let recorded = |metric: Metric| match &case.computed {
            Some(c) => c.get(m).is_some_and(|ms| ms.contains(&metric)),
            None => metric.recorded_by(kind, case.references),
        };
        if let Some(s) = &claim.statistic
            && !recorded(s.metric)
        {
            let why = if case.computed.is_some() {
                " (a computed case)"
            } else if case.references {
                ""
            } else {
                " (the scenario has no reference frames)"
            };
            return Err(at(format!(
                "method '{m}' ({kind}) does not record the statistic {}{why}",
                s.metric.name()
            )));
        }
        if let Some(s) = &claim.statistic
            && let Some(FolderInput::EventAndMap { map, writers }) =
                s.metric.from_images_by().map(|i| i.input)
        {
            let written = case.image_maps.get(map).map_or(&[][..], |w| &w[..]);
            if !written.iter().any(|p| p == m) {
                return Err(at(format!(
                    "method '{m}' writes no {map} maps, so it has no {}; expected {writers}: {}",
                    s.metric.name(),
                    written.join(", ")
                )));
            }
        }
    }
    Ok(())
}

/// Each `variant_of` names another claim of the file that is no variant itself.
fn check_variants(file: RonFile, claims: &[Claim]) -> Result<(), ScenarioError> {
    for c in claims {
        let Some(v) = &c.variant_of else { continue };
        let at = |m: String| file.error(Some((c.line, 1)), format!("claim '{}': {m}", c.id));
        match claims.iter().find(|b| b.id == v.claim) {
            None => {
                return Err(at(format!(
                    "variant_of: no claim '{}' in this file; expected the id of the claim this one switches a condition of",
                    v.claim
                )));
            }
            Some(b) if b.id == c.id || b.variant_of.is_some() => {
                return Err(at(format!(
                    "variant_of: '{}' is itself a variant (or this claim); expected the claim judged under the other condition",
                    v.claim
                )));
            }
            Some(_) if v.switched.trim().is_empty() => {
                return Err(at("variant_of: switched is empty; expected what differs, e.g. \"irradiance: PathTraced\"".into()));
            }
            Some(_) => {}
        }
    }
    Ok(())
}

impl Claims {
    pub fn load(path: &Path) -> Result<Claims, ScenarioError> {
        Self::from_ron(&ron_file::read(path, "claims file")?, path)
    }

    pub fn from_ron(text: &str, origin: &Path) -> Result<Claims, ScenarioError> {
        let file = RonFile { text, origin };
        let parsed: ClaimsFile = file.parse()?;
        let folder = origin.parent().unwrap_or(Path::new(""));
        let mut cases: Vec<ClaimCase> = Vec::new();
        let mut methods: BTreeMap<String, CaseMethods> = BTreeMap::new();
        let mut case_lines = BTreeMap::new();
        let mut events: BTreeMap<String, CaseEvents> = BTreeMap::new();
        for entry in file.entries("cases", &parsed.cases) {
            let (case, case_methods, case_events) = read_case(file, &entry, folder, &cases)?;
            events.insert(case.name.clone(), case_events);
            methods.insert(case.name.clone(), case_methods);
            case_lines.insert(case.name.clone(), (entry.line, entry.column));
            cases.push(case);
        }
        let mut claims: Vec<Claim> = Vec::new();
        // Per case, the reference method of its metrics computed from images.
        let mut against: BTreeMap<String, String> = BTreeMap::new();
        // Per case, the passes its methods' FrameMs leaves out.
        let mut not_run: BTreeMap<String, Vec<(String, Vec<String>)>> = BTreeMap::new();
        for entry in file.entries("claims", &parsed.claims) {
            let claim =
                read_claim(file, &entry, &claims, &methods, &events, &mut against, &mut not_run)?;
            claims.push(claim);
        }
        if claims.is_empty() {
            return Err(file.error(None, "no claims; expected at least one".into()));
        }
        check_variants(file, &claims)?;
        Ok(Claims {
            paper: parsed.paper,
            title: parsed.title,
            cases,
            claims,
            origin: origin.to_path_buf(),
            case_lines,
        })
    }

    /// A case's seeds at `scale`: the file's first `n` seeds, continued upwards past its last
    /// when `n` (`--seeds`, else the scale's `seeds`) is larger.
    pub fn seeds_of(&self, c: &ClaimCase, scale: Scale, seeds: Option<usize>) -> Vec<u64> {
        let size = match scale {
            Scale::Smoke => &c.smoke,
            Scale::Lab => &c.lab,
            Scale::Paper => &c.paper,
        };
        let mut s = c.seeds.clone();
        if let Some(n) = seeds.or(size.seeds) {
            let last = *s.iter().max().unwrap_or(&0);
            s.truncate(n);
            s.extend((1..).map(|i| last + i).take(n.saturating_sub(s.len())));
        }
        s
    }

    /// The suite cases the comparable claims need, sized for `scale`, each with `seeds` (the
    /// file's first `n` seeds, continued upwards past its last when `n` is larger).
    pub fn cases_for(&self, scale: Scale, seeds: Option<usize>) -> Vec<Case> {
        let needed: Vec<&str> = self
            .claims
            .iter()
            .filter(|c| !matches!(c.comparison, Comparison::NotComparable { .. }))
            .filter_map(|c| c.case.as_deref())
            .collect();
        // A case with tables of its own is played for them even where no claim needs it.
        self.cases
            .iter()
            .filter(|c| {
                needed.contains(&c.name.as_str()) || !c.table.is_empty() || c.by_window.is_some()
            })
            .filter_map(|c| c.scenario.as_ref().map(|scenario| (c, scenario)))
            .map(|(c, scenario)| {
                let size = match scale {
                    Scale::Smoke => &c.smoke,
                    Scale::Lab => &c.lab,
                    Scale::Paper => &c.paper,
                };
                let s = self.seeds_of(c, scale, seeds);
                let (line, column) = self.case_lines.get(&c.name).copied().unwrap_or((1, 1));
                Case {
                    name: c.name.clone(),
                    scenario: scenario.clone(),
                    measure: None,
                    seeds: s,
                    frames: size.frames,
                    resolution: size.resolution,
                    spp: size.spp,
                    methods: c.methods.clone(),
                    params: size.params.clone(),
                    entry: Some(sim::scenario::MethodEntry { text: String::new(), line, column }),
                }
            })
            .collect()
    }
}
