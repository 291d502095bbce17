//! Reading a scenario file: the file as written (`ScenarioFile`), parsed, its paths resolved
//! against the file's folder, and its values checked (here, and in `meaningless`) before it
//! becomes a [`Scenario`].

use std::path::{Path, PathBuf};

use glam::Vec3;
use scene::DensityKind;
use serde::{Deserialize, Serialize};

use crate::scenario::{
    AnimationSpec, CameraSpec, EventSpec, MaterialOverride, ReferenceSpec, Region, Scenario,
    ScenarioError, SceneSource, find_quoted, line_col, raw_entries,
};

fn default_time_step() -> f32 {
    1.0 / 30.0
}
fn default_max_depth() -> u32 {
    8
}
/// ε of the SMAPE denominator, reliability-weighted-nirc.txt §4.2.
fn default_smape_epsilon() -> f32 {
    0.01
}

/// The file as written. Public and serialisable only so that the scenario reference's test
/// (tests/docs_settings.rs) reads its fields and defaults from serde rather than from prose.
#[derive(Deserialize, Serialize)]
#[serde(rename = "Scenario", deny_unknown_fields)]
pub struct ScenarioFile {
    #[serde(default)]
    name: Option<String>,
    scene: SceneSource,
    #[serde(default)]
    camera: Option<CameraSpec>,
    #[serde(default)]
    environment: Option<Vec3>,
    resolution: (u32, u32),
    frames: u32,
    #[serde(default)]
    warmup_frames: u32,
    #[serde(default = "default_time_step")]
    time_step: f32,
    #[serde(default)]
    seed: u64,
    #[serde(default)]
    output: Option<PathBuf>,
    #[serde(default = "default_max_depth")]
    max_depth: u32,
    methods: Vec<Box<ron::value::RawValue>>,
    #[serde(default)]
    reference: ReferenceSpec,
    #[serde(default)]
    regions: Vec<Region>,
    #[serde(default = "default_smape_epsilon")]
    smape_epsilon: f32,
    #[serde(default)]
    animations: Vec<AnimationSpec>,
    #[serde(default)]
    events: Vec<EventSpec>,
    #[serde(default)]
    cvvdp: metrics::CvvdpSettings,
    #[serde(default)]
    media: Vec<scene::MediumDesc>,
    #[serde(default)]
    materials: Vec<MaterialOverride>,
}

impl Scenario {
    /// Reads and checks a scenario file.
    pub fn load(path: &Path) -> Result<Scenario, ScenarioError> {
        let text = std::fs::read_to_string(path).map_err(|e| ScenarioError {
            file: path.to_path_buf(),
            position: None,
            message: format!("cannot read scenario file: {e}"),
        })?;
        Self::from_ron(&text, path)
    }

    /// Parses scenario text; `origin` is the file it came from (names it in errors and
    /// anchors relative glTF paths).
    pub fn from_ron(text: &str, origin: &Path) -> Result<Scenario, ScenarioError> {
        let options = ron::Options::default()
            .with_default_extension(ron::extensions::Extensions::IMPLICIT_SOME);
        let mut file: ScenarioFile = options.from_str(text).map_err(|e| ScenarioError {
            file: origin.to_path_buf(),
            position: Some((e.span.start.line, e.span.start.col)),
            message: e.code.to_string(),
        })?;
        let invalid = |what: &str, message: String| ScenarioError {
            file: origin.to_path_buf(),
            position: text.find(&format!("{what}:")).map(|at| {
                let before = &text[..at];
                (
                    before.matches('\n').count() + 1,
                    before.len() - before.rfind('\n').map_or(0, |i| i + 1) + 1,
                )
            }),
            message,
        };
        let (w, h) = file.resolution;
        if w == 0 || h == 0 {
            return Err(invalid(
                "resolution",
                format!("resolution {w}x{h}; expected both sides > 0"),
            ));
        }
        if file.frames == 0 {
            return Err(invalid("frames", "frames: 0; expected at least 1 frame".into()));
        }
        if !(file.time_step > 0.0 && file.time_step.is_finite()) {
            return Err(invalid(
                "time_step",
                format!("time_step {}; expected a positive number of seconds", file.time_step),
            ));
        }
        if file.methods.is_empty() {
            return Err(invalid(
                "methods",
                "no methods; expected e.g. [PathTracing(spp: 4)]".into(),
            ));
        }
        for r in &file.regions {
            if r.width == 0 || r.height == 0 || r.x + r.width > w || r.y + r.height > h {
                return Err(ScenarioError {
                    file: origin.to_path_buf(),
                    position: find_quoted(text, &r.name),
                    message: format!(
                        "region '{}' ({}, {}, {}x{}) is empty or leaves the {w}x{h} image; expected a rectangle inside it",
                        r.name, r.x, r.y, r.width, r.height
                    ),
                });
            }
        }
        for m in &mut file.media {
            if let DensityKind::Grid { file: grid } = &mut m.kind {
                if grid.is_relative() {
                    *grid = origin.parent().unwrap_or(Path::new("")).join(&*grid);
                }
                if let Err(e) = scene::RawGrid::load(grid) {
                    return Err(ScenarioError {
                        file: origin.to_path_buf(),
                        position: find_quoted(text, &m.name),
                        message: format!("medium '{}': {e}", m.name),
                    });
                }
            }
        }
        for m in &mut file.media {
            m.bound.resolve(origin.parent().unwrap_or(Path::new("")));
            if let Err(e) = m.bound.mesh(m.box_min, m.box_max) {
                return Err(ScenarioError {
                    file: origin.to_path_buf(),
                    position: find_quoted(text, &m.name),
                    message: format!("medium '{}': bound: {e}", m.name),
                });
            }
        }
        for m in &file.media {
            if let Some(message) = m.problem() {
                return Err(ScenarioError {
                    file: origin.to_path_buf(),
                    position: find_quoted(text, &m.name)
                        .or_else(|| invalid("media", String::new()).position),
                    message,
                });
            }
            if file.media.iter().filter(|o| o.name == m.name).count() > 1 {
                return Err(ScenarioError {
                    file: origin.to_path_buf(),
                    position: find_quoted(text, &m.name),
                    message: format!("two media named '{}'; expected unique names", m.name),
                });
            }
        }
        if file.reference.random_walk && !file.media.is_empty() {
            return Err(ScenarioError {
                file: origin.to_path_buf(),
                position: text.find("random_walk").map(|at| line_col(text, at)),
                message: "reference: random_walk with media; expected a scenario without media (the random walk renders subsurface materials only)".into(),
            });
        }
        for m in &file.materials {
            if let Some(sss) = &m.subsurface {
                let d = sss.dmfp;
                if !(d.min_element() > 0.0 && d.is_finite()) {
                    return Err(ScenarioError {
                        file: origin.to_path_buf(),
                        position: find_quoted(text, &m.material)
                            .or_else(|| invalid("materials", String::new()).position),
                        message: format!(
                            "material '{}': subsurface dmfp ({}, {}, {}); expected three positive diffuse mean free paths in scene units",
                            m.material, d.x, d.y, d.z
                        ),
                    });
                }
            }
        }
        if let Some((at, key, literal)) = crate::finite::first_non_finite(text) {
            return Err(ScenarioError {
                file: origin.to_path_buf(),
                position: Some(line_col(text, at)),
                message: format!(
                    "{key}: {literal} is not a finite number; expected a finite number"
                ),
            });
        }
        if let Some(message) = file.cvvdp.problem() {
            return Err(ScenarioError {
                file: origin.to_path_buf(),
                position: find_quoted(text, &file.cvvdp.display)
                    .or_else(|| invalid("cvvdp", String::new()).position),
                message: format!("cvvdp: {message}"),
            });
        }
        let name = file.name.unwrap_or_else(|| {
            origin
                .file_stem()
                .map(|s| s.to_string_lossy().into_owned())
                .unwrap_or_else(|| "scenario".into())
        });
        let scene = match file.scene {
            SceneSource::Gltf(p) if p.is_relative() => {
                SceneSource::Gltf(origin.parent().unwrap_or(Path::new("")).join(p))
            }
            other => other,
        };
        let output = file.output.unwrap_or_else(|| PathBuf::from("runs").join(&name));
        let methods = raw_entries(text, "methods", &file.methods);
        let scenario = Scenario {
            name,
            scene,
            camera: file.camera,
            environment: file.environment,
            resolution: file.resolution,
            frames: file.frames,
            warmup_frames: file.warmup_frames,
            time_step: file.time_step,
            seed: file.seed,
            output,
            max_depth: file.max_depth,
            methods,
            reference: file.reference,
            regions: file.regions,
            smape_epsilon: file.smape_epsilon,
            animations: file.animations,
            events: file.events,
            cvvdp: file.cvvdp,
            media: file.media,
            materials: file.materials,
            origin: origin.to_path_buf(),
            source: text.to_string(),
        };
        crate::meaningless::check(&scenario)?;
        Ok(scenario)
    }
}
