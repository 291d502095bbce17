//! A scenario ready to run: the world's part (`sim::Scenario`), its methods parsed by their own
//! settings structs, and the command line's overrides applied. Every input error surfaces here,
//! before anything is written.

use std::path::{Path, PathBuf};

use anyhow::{Result, bail};
use sim::Scenario;

use crate::methods::{Method, check_labels, parse_methods};

/// Command-line overrides of the scenario's own settings.
#[derive(Clone, Debug, Default)]
pub struct Overrides {
    pub frames: Option<u32>,
    pub resolution: Option<(u32, u32)>,
    pub spp: Option<u32>,
    pub seed: Option<u64>,
    pub out: Option<PathBuf>,
}

/// A scenario and its methods.
#[derive(Clone, Debug)]
pub struct RunSpec {
    pub scenario: Scenario,
    pub methods: Vec<Method>,
}

impl RunSpec {
    /// Loads the scenario, parses its methods and applies the overrides.
    pub fn load(path: &Path, o: &Overrides) -> Result<RunSpec> {
        let scenario = Scenario::load(path)?;
        Self::from_scenario(scenario, o)
    }

    /// [`Self::load`] for a scenario already read (tests, tools).
    pub fn from_scenario(mut scenario: Scenario, o: &Overrides) -> Result<RunSpec> {
        let path = scenario.origin.clone();
        let mut methods = parse_methods(&scenario)?;
        if let Some(f) = o.frames {
            scenario.frames = f;
        }
        if let Some(r) = o.resolution {
            scenario.resolution = r;
        }
        if let Some(spp) = o.spp {
            for m in &mut methods {
                m.spec.set_spp(spp);
            }
            check_labels(&scenario, &methods)
                .map_err(|e| anyhow::anyhow!("{e} (after --spp {spp})"))?;
        }
        if let Some(s) = o.seed {
            scenario.seed = s;
        }
        if let Some(out) = &o.out {
            scenario.output = out.clone();
        }
        if scenario.frames == 0 {
            bail!("{}: frames must be at least 1", path.display());
        }
        if !(scenario.smape_epsilon.is_finite() && scenario.smape_epsilon >= 0.0) {
            bail!(
                "{}: smape_epsilon must be a finite number >= 0, got {}",
                path.display(),
                scenario.smape_epsilon
            );
        }
        if methods.is_empty() {
            bail!(
                "{}: no methods to run; add e.g. `methods: [PathTracing(spp: 1)]`",
                path.display()
            );
        }
        Ok(RunSpec { scenario, methods })
    }
}

/// The scene a built-in name builds, at frame 0.
pub fn builtin_scene(name: &str, resolution: (u32, u32)) -> Result<render::scene::SceneDesc> {
    let text = format!(
        "Scenario(scene: Builtin(\"{name}\"), resolution: ({}, {}), frames: 1, methods: [PathTracing(spp: 1)])",
        resolution.0, resolution.1
    );
    let scenario = Scenario::from_ron(&text, Path::new("<bench>"))?;
    let sim = sim::Simulation::new(&scenario)?;
    Ok(sim.scene().clone())
}
