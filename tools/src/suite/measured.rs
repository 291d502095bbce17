//! A suite case over frames on disk instead of a scenario: the folders `flicker measure` reads
//! (crate::measure), so that another renderer's CI gates on flicker's metrics without rendering
//! anything here. Seeds, when given, are substituted for `{seed}` in the folders' paths: one
//! rendering per seed gives the spread that relative gates need.

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

use metrics::CvvdpSettings;
use serde::Deserialize;

use crate::measure::MeasureOptions;

/// What a folder path holds where the seed goes.
pub const SEED: &str = "{seed}";

/// `measure: (reference: DIR, tests: {NAME: DIR}, motion: {NAME: DIR}, fps: 30, events: [..])`.
#[derive(Clone, Debug, PartialEq, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct MeasuredFrames {
    /// The reference sequence (EXR or PNG, frame numbers from file names).
    pub reference: PathBuf,
    /// Test sequences by name: the names are the methods gates and baselines know.
    pub tests: BTreeMap<String, PathBuf>,
    /// Motion vectors of tests by test name, for reprojected SMAPE.
    #[serde(default)]
    pub motion: BTreeMap<String, PathBuf>,
    #[serde(default = "default_fps")]
    pub fps: f64,
    /// Frames of events, in the input's frame numbers: the windows' events.
    #[serde(default)]
    pub events: Vec<u32>,
    /// JOD's display model and exposure [default: those of `flicker measure`].
    #[serde(default)]
    pub cvvdp: CvvdpSettings,
}

fn default_fps() -> f64 {
    30.0
}

fn with_seed(path: &Path, seed: u64) -> PathBuf {
    PathBuf::from(path.to_string_lossy().replace(SEED, &seed.to_string()))
}

impl MeasuredFrames {
    fn paths_mut(&mut self) -> impl Iterator<Item = &mut PathBuf> {
        std::iter::once(&mut self.reference)
            .chain(self.tests.values_mut())
            .chain(self.motion.values_mut())
    }

    /// Relative folders are resolved against the suite file's folder.
    pub fn resolve(&mut self, folder: &Path) {
        for p in self.paths_mut().filter(|p| p.is_relative()) {
            *p = folder.join(&*p);
        }
    }

    /// What is wrong with the case, if anything: no tests, or seeds that would measure the same
    /// frames each time (a test folder without `{seed}`), or `{seed}` without seeds.
    pub fn problem(&self, seeded: bool) -> Option<String> {
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
        let mut all =
            std::iter::once(&self.reference).chain(self.tests.values()).chain(self.motion.values());
        if !seeded && let Some(p) = all.find(|p| has_seed(p)) {
            return Some(format!(
                "{} names {SEED}, but the case has no seeds; expected seeds: [1, 2, 3]",
                p.display()
            ));
        }
        None
    }

    /// `flicker measure`'s options for one seed's run folder `out` (a case without seeds has
    /// seed 0 and no `{seed}` in its folders).
    pub fn options(&self, seed: u64, out: &Path) -> MeasureOptions {
        let named = |m: &BTreeMap<String, PathBuf>| {
            m.iter().map(|(n, p)| (n.clone(), with_seed(p, seed))).collect()
        };
        MeasureOptions {
            reference: with_seed(&self.reference, seed),
            tests: named(&self.tests),
            motion: named(&self.motion),
            fps: self.fps,
            events: self.events.clone(),
            labels: Vec::new(),
            timings: Vec::new(),
            out: out.to_path_buf(),
            cvvdp: self.cvvdp.clone(),
            smape_epsilon: metrics::smape::DEFAULT_EPS,
        }
    }
}
