//! A suite case over frames on disk instead of a scenario: the folders `flicker measure` reads
//! (crate::measure), so that another renderer's CI gates on flicker's metrics without rendering
//! anything here. Seeds, when given, are substituted for `{seed}` in the folders' paths: one
//! rendering per seed gives the spread that relative gates need. A case may name a `flicker
//! export` package instead of a reference folder (its references, frame rate, events and display,
//! as `flicker measure --scenario`), and per-test timings (as `--timings`) for FrameMs gates.

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

use metrics::CvvdpSettings;
use serde::Deserialize;

use crate::export::Package;
use crate::measure::MeasureOptions;

/// What a folder path holds where the seed goes.
pub const SEED: &str = "{seed}";

/// `measure: (reference: DIR | scenario: PACKAGE, tests: {NAME: DIR}, motion: {NAME: DIR},
/// timings: {NAME: FILE}, fps: 30, events: [..])`.
#[derive(Clone, Debug, PartialEq, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct MeasuredFrames {
    /// The reference sequence (EXR or PNG, frame numbers from file names).
    #[serde(default)]
    pub reference: Option<PathBuf>,
    /// A `flicker export` package instead of `reference`: its references, and its frame rate,
    /// events, display and SMAPE ε unless given here.
    #[serde(default)]
    pub scenario: Option<PathBuf>,
    /// Test sequences by name: the names are the methods gates and baselines know.
    pub tests: BTreeMap<String, PathBuf>,
    /// Motion vectors of tests by test name, for reprojected SMAPE.
    #[serde(default)]
    pub motion: BTreeMap<String, PathBuf>,
    /// Per-frame times of tests by test name (CSV, `crate::measure::Timings`): FrameMs gates.
    #[serde(default)]
    pub timings: BTreeMap<String, PathBuf>,
    /// Frames per second [default: the package's, else 30].
    #[serde(default)]
    pub fps: Option<f64>,
    /// Frames of events, in the input's frame numbers: the windows' events [default: the
    /// package's].
    #[serde(default)]
    pub events: Vec<u32>,
    /// JOD's display model and exposure [default: the package's, else `flicker measure`'s].
    #[serde(default)]
    pub cvvdp: Option<CvvdpSettings>,
}

const DEFAULT_FPS: f64 = 30.0;

fn with_seed(path: &Path, seed: u64) -> PathBuf {
    PathBuf::from(path.to_string_lossy().replace(SEED, &seed.to_string()))
}

impl MeasuredFrames {
    fn paths_mut(&mut self) -> impl Iterator<Item = &mut PathBuf> {
        self.reference
            .iter_mut()
            .chain(self.scenario.iter_mut())
            .chain(self.tests.values_mut())
            .chain(self.motion.values_mut())
            .chain(self.timings.values_mut())
    }

    /// Relative folders are resolved against the suite file's folder.
    pub fn resolve(&mut self, folder: &Path) {
        for p in self.paths_mut().filter(|p| p.is_relative()) {
            *p = folder.join(&*p);
        }
    }

    /// What is wrong with the case, if anything: no tests, neither or both of a reference and a
    /// package, timings of no test, seeds that would measure the same frames each time (a test
    /// folder without `{seed}`), or `{seed}` without seeds.
    pub fn problem(&self, seeded: bool) -> Option<String> {
        match (&self.reference, &self.scenario) {
            (None, None) => {
                return Some(
                    "measure has no reference; expected reference: \"DIR\" or scenario: \"PACKAGE\" (a `flicker export` package)".into(),
                );
            }
            (Some(_), Some(_)) => {
                return Some(
                    "measure names a reference and a scenario package; expected one of them (the package holds its references)".into(),
                );
            }
            _ => {}
        }
        if self.tests.is_empty() {
            return Some(
                "measure names no tests; expected e.g. tests: {\"mine\": \"frames/mine\"}".into(),
            );
        }
        let has_seed = |p: &PathBuf| p.to_string_lossy().contains(SEED);
        if seeded && let Some((name, _)) = self.tests.iter().find(|(_, p)| !has_seed(p)) {
            return Some(format!(
                "test '{name}' has no {SEED} in its folder, so every seed would measure the same frames; expected e.g. \"frames/{name}_{SEED}\""
            ));
        }
        for (what, names) in [("motion", &self.motion), ("timings", &self.timings)] {
            if let Some(name) = names.keys().find(|n| !self.tests.contains_key(*n)) {
                return Some(format!(
                    "{what} names '{name}', which is not a test; expected one of: {}",
                    self.tests.keys().cloned().collect::<Vec<_>>().join(", ")
                ));
            }
        }
        let mut all = self
            .reference
            .iter()
            .chain(self.scenario.iter())
            .chain(self.tests.values())
            .chain(self.motion.values())
            .chain(self.timings.values());
        if !seeded && let Some(p) = all.find(|p| has_seed(p)) {
            return Some(format!(
                "{} names {SEED}, but the case has no seeds; expected seeds: [1, 2, 3]",
                p.display()
            ));
        }
        None
    }

    /// `flicker measure`'s options for one seed's run folder `out` (a case without seeds has
    /// seed 0 and no `{seed}` in its folders); a package is read (and its reference frames
    /// checked) here.
    pub fn options(&self, seed: u64, out: &Path) -> anyhow::Result<MeasureOptions> {
        let named = |m: &BTreeMap<String, PathBuf>| {
            m.iter().map(|(n, p)| (n.clone(), with_seed(p, seed))).collect()
        };
        let package = match &self.scenario {
            Some(dir) => Some(Package::read(&with_seed(dir, seed))?),
            None => None,
        };
        let p = package.as_ref();
        let (events, labels) = match p {
            Some(p) if self.events.is_empty() => p.events.iter().cloned().unzip(),
            _ => (self.events.clone(), Vec::new()),
        };
        let reference = match (p, &self.reference) {
            (Some(p), _) => p.reference.clone(),
            (None, Some(r)) => with_seed(r, seed),
            (None, None) => anyhow::bail!("measure has no reference"),
        };
        Ok(MeasureOptions {
            reference,
            tests: named(&self.tests),
            motion: named(&self.motion),
            fps: self.fps.or(p.map(|p| p.fps)).unwrap_or(DEFAULT_FPS),
            events,
            labels,
            timings: named(&self.timings),
            out: out.to_path_buf(),
            cvvdp: self.cvvdp.clone().or(p.map(|p| p.cvvdp.clone())).unwrap_or_default(),
            smape_epsilon: p.map_or(metrics::smape::DEFAULT_EPS, |p| p.smape_epsilon),
        })
    }
}
