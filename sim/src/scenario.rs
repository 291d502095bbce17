//! Scenario files (RON): what to load, what moves, what to render and measure.
//!
//! Optional fields may be written bare (`camera: (position: ..)`): the `implicit_some`
//! extension is on. Errors carry the file, line and column and say what was expected.

use std::fmt;
use std::path::PathBuf;

use glam::Vec3;
use serde::{Deserialize, Deserializer, Serialize};

/// Where the scene comes from.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub enum SceneSource {
    /// A built-in scene by name (see [`crate::scenes::names`]).
    Builtin(#[serde(deserialize_with = "builtin_name")] String),
    /// A glTF file; relative paths are resolved against the scenario file's folder.
    Gltf(PathBuf),
}

fn builtin_name<'de, D: Deserializer<'de>>(d: D) -> Result<String, D::Error> {
    let name = String::deserialize(d)?;
    if crate::scenes::names().contains(&name.as_str()) {
        Ok(name)
    } else {
        Err(serde::de::Error::custom(format!(
            "unknown scene '{name}'; expected one of: {}",
            crate::scenes::names().join(", ")
        )))
    }
}

/// One entry of the scenario's `methods: [...]`, as written. The world knows nothing of
/// rendering methods (`playback` parses them, each with its own settings struct); it keeps each
/// entry's text and its place in the file, so a method's errors point at the file's line.
#[derive(Clone, Debug, PartialEq, Eq, Serialize)]
pub struct MethodEntry {
    /// The entry's RON text, e.g. `SampleCache(retrace: Multi)`.
    pub text: String,
    /// 1-based line and column of the entry in the scenario file.
    pub line: usize,
    pub column: usize,
}

impl MethodEntry {
    /// An entry that is not from a file (tests, tools); its place is line 1, column 1.
    pub fn new(text: impl Into<String>) -> Self {
        Self { text: text.into(), line: 1, column: 1 }
    }

    /// The file position of a (1-based) line and column inside the entry's text.
    pub fn position_in_file(&self, line: usize, column: usize) -> (usize, usize) {
        if line <= 1 {
            (self.line, self.column + column.saturating_sub(1))
        } else {
            (self.line + line - 1, column)
        }
    }
}

/// Which frames get a path-traced reference.
#[derive(Clone, Debug, PartialEq, Eq, Serialize, Deserialize)]
pub enum ReferenceFrames {
    None,
    List(Vec<u32>),
    /// Frames 0, n, 2n, ...
    Every(u32),
}

#[derive(Clone, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ReferenceSpec {
    pub spp: u32,
    pub frames: ReferenceFrames,
    /// Subsurface materials as homogeneous media inside their meshes, rendered by a random walk
    /// (media::gpu::SubsurfacePathPass; coefficients by scene::SubsurfaceMedium): the ground
    /// truth of the screen-space SSS. Off: subsurface materials shade as their diffuse base.
    #[serde(default, skip_serializing_if = "std::ops::Not::not")]
    pub random_walk: bool,
}

impl Default for ReferenceSpec {
    fn default() -> Self {
        Self { spp: 64, frames: ReferenceFrames::None, random_walk: false }
    }
}

impl ReferenceSpec {
    /// Whether frame `frame` of a `total`-frame run needs a reference.
    pub fn wants(&self, frame: u32, total: u32) -> bool {
        if frame >= total || self.spp == 0 {
            return false;
        }
        match &self.frames {
            ReferenceFrames::None => false,
            ReferenceFrames::List(list) => list.contains(&frame),
            ReferenceFrames::Every(n) => *n > 0 && frame.is_multiple_of(*n),
        }
    }
}

/// A named rectangle of the image (pixels), for metrics over a part of the frame.
#[derive(Clone, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Region {
    pub name: String,
    pub x: u32,
    pub y: u32,
    #[serde(alias = "w")]
    pub width: u32,
    #[serde(alias = "h")]
    pub height: u32,
}

fn default_up() -> Vec3 {
    Vec3::Y
}
fn default_vfov() -> f32 {
    45.0
}

/// A pinhole camera replacing the scene's.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct CameraSpec {
    pub position: Vec3,
    pub target: Vec3,
    #[serde(default = "default_up")]
    pub up: Vec3,
    #[serde(default = "default_vfov")]
    pub vfov_degrees: f32,
}

#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct AxisAngle {
    pub axis: Vec3,
    pub degrees: f32,
}

#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub enum WaveformSpec {
    /// I(t) = I0 (sin 2πft + 1)
    Sine { frequency: f32 },
    /// On for half of each `period` seconds.
    Square { period: f32 },
    /// Each frame on with this probability (seeded).
    Strobe { probability: f32 },
}

/// A transform key; missing parts keep the entity's rest pose.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct KeySpec {
    pub frame: f32,
    #[serde(default)]
    pub translation: Option<Vec3>,
    #[serde(default)]
    pub rotation: Option<AxisAngle>,
    #[serde(default)]
    pub scale: Option<Vec3>,
}

#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct CameraKeySpec {
    pub frame: f32,
    pub position: Vec3,
    pub target: Vec3,
    #[serde(default)]
    pub vfov_degrees: Option<f32>,
}

/// An animation attached to named entities.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub enum AnimationSpec {
    /// Continuous rotation about an axis through the entity's origin.
    Rotate { entity: String, axis: Vec3, degrees_per_second: f32 },
    /// One rotation by `degrees` at frame `frame`.
    RotateOnce { entity: String, axis: Vec3, degrees: f32, frame: u32 },
    /// Intensity waveform of a light or emissive mesh.
    Flash { entity: String, waveform: WaveformSpec },
    /// `count` copies of the prototype's mesh flocking inside a box (the prototype hides).
    Boids {
        prototype: String,
        count: u32,
        #[serde(default)]
        bounds_min: Option<Vec3>,
        #[serde(default)]
        bounds_max: Option<Vec3>,
        #[serde(default)]
        separation: Option<f32>,
        #[serde(default)]
        view_radius: Option<f32>,
        #[serde(default)]
        max_speed: Option<f32>,
        #[serde(default)]
        min_speed: Option<f32>,
    },
    Keyframes {
        entity: String,
        keys: Vec<KeySpec>,
        #[serde(default)]
        repeat: bool,
    },
    /// A path for the active camera.
    CameraPath {
        keys: Vec<CameraKeySpec>,
        #[serde(default)]
        repeat: bool,
    },
}

#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub enum ActionSpec {
    RotateLight {
        light: String,
        axis: Vec3,
        degrees: f32,
    },
    Rotate {
        entity: String,
        axis: Vec3,
        degrees: f32,
    },
    /// Switch a light or an emissive mesh off (or back on).
    Toggle {
        entity: String,
    },
    MoveTo {
        entity: String,
        translation: Vec3,
    },
    MoveBy {
        entity: String,
        offset: Vec3,
    },
    SetMaterial {
        material: String,
        #[serde(default)]
        base_color: Option<Vec3>,
        #[serde(default)]
        emission: Option<Vec3>,
        #[serde(default)]
        roughness: Option<f32>,
        #[serde(default)]
        metallic: Option<f32>,
    },
}

#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct EventSpec {
    pub frame: u32,
    pub action: ActionSpec,
}

/// A scenario's change to one of the scene's materials, by name:
/// `(material: "skin", subsurface: (dmfp: (0.3, 0.12, 0.06)))`.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct MaterialOverride {
    pub material: String,
    /// Makes the material a subsurface material (sss).
    #[serde(default)]
    pub subsurface: Option<scene::Subsurface>,
}

/// A scenario ready to play.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Scenario {
    /// Defaults to the file's stem.
    pub name: String,
    /// glTF paths are already resolved against the scenario file's folder.
    pub scene: SceneSource,
    pub camera: Option<CameraSpec>,
    /// Replaces the scene's environment radiance.
    pub environment: Option<Vec3>,
    pub resolution: (u32, u32),
    pub frames: u32,
    pub warmup_frames: u32,
    /// Seconds per frame.
    pub time_step: f32,
    pub seed: u64,
    /// Defaults to `runs/<name>` (relative to the working directory).
    pub output: PathBuf,
    pub max_depth: u32,
    /// The methods as written; `playback` parses them.
    pub methods: Vec<MethodEntry>,
    pub reference: ReferenceSpec,
    pub regions: Vec<Region>,
    /// ε in SMAPE's denominator 2|a - b| / (|a| + |b| + ε).
    pub smape_epsilon: f32,
    pub animations: Vec<AnimationSpec>,
    pub events: Vec<EventSpec>,
    /// How ColorVideoVDP's JOD sees the run: display model, exposure (metrics::cvvdp).
    pub cvvdp: metrics::CvvdpSettings,
    /// Participating media (scene::medium); none by default, and then nothing is paid for them
    /// (not even a key in the manifest).
    #[serde(skip_serializing_if = "Vec::is_empty")]
    pub media: Vec<scene::MediumDesc>,
    /// Material overrides (subsurface parameters), applied when the scene is spawned.
    #[serde(skip_serializing_if = "Vec::is_empty")]
    pub materials: Vec<MaterialOverride>,
    /// The RON file this came from (used in error messages).
    pub origin: PathBuf,
    /// The RON text, to point errors found later (unknown entity names) at a line.
    #[serde(skip)]
    pub source: String,
}

/// A scenario file that could not be used: "path:line:col: what was expected".
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
pub struct ScenarioError {
    pub file: PathBuf,
    /// 1-based line and column, when the problem has a place in the text.
    pub position: Option<(usize, usize)>,
    pub message: String,
}

impl fmt::Display for ScenarioError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self.position {
            Some((line, col)) => {
                write!(f, "{}:{line}:{col}: {}", self.file.display(), self.message)
            }
            None => write!(f, "{}: {}", self.file.display(), self.message),
        }
    }
}

/// Each entry's text and where it starts: entries of a list kept as raw RON (`methods`, a
/// suite's `cases` and `gates`) are found in file order after `key`, so that errors found when
/// an entry is parsed later point at the file's line.
pub fn raw_entries(text: &str, key: &str, raw: &[Box<ron::value::RawValue>]) -> Vec<MethodEntry> {
    let mut from = text.find(key).unwrap_or(0);
    raw.iter()
        .map(|r| {
            let ron = r.get_ron().trim();
            let at = text[from..].find(ron).map_or(from, |i| from + i);
            from = at + ron.len();
            let (line, column) = line_col(text, at);
            MethodEntry { text: ron.to_string(), line, column }
        })
        .collect()
}

/// 1-based line and column of byte offset `at`.
pub fn line_col(text: &str, at: usize) -> (usize, usize) {
    let before = &text[..at];
    (before.matches('\n').count() + 1, before.len() - before.rfind('\n').map_or(0, |i| i + 1) + 1)
}

/// Line and column (1-based) of the first quoted occurrence of `needle` in `text`.
pub fn find_quoted(text: &str, needle: &str) -> Option<(usize, usize)> {
    let at = text.find(&format!("\"{needle}\""))?;
    let before = &text[..at];
    let line = before.matches('\n').count() + 1;
    let col = before.len() - before.rfind('\n').map_or(0, |i| i + 1) + 1;
    Some((line, col))
}

fn axis_label(v: Vec3) -> String {
    format!("({}, {}, {})", v.x, v.y, v.z)
}

impl Scenario {
    /// Discrete changes by frame, for charts: scripted events and one-shot rotations.
    pub fn events_summary(&self) -> Vec<(u32, String)> {
        let mut out: Vec<(u32, String)> = Vec::new();
        for a in &self.animations {
            if let AnimationSpec::RotateOnce { entity, degrees, frame, .. } = a {
                out.push((*frame, format!("rotate '{entity}' by {degrees}°")));
            }
        }
        for e in &self.events {
            let text = match &e.action {
                ActionSpec::RotateLight { light, degrees, .. } => {
                    format!("rotate light '{light}' by {degrees}°")
                }
                ActionSpec::Rotate { entity, degrees, .. } => {
                    format!("rotate '{entity}' by {degrees}°")
                }
                ActionSpec::Toggle { entity } => format!("toggle '{entity}'"),
                ActionSpec::MoveTo { entity, translation } => {
                    format!("move '{entity}' to {}", axis_label(*translation))
                }
                ActionSpec::MoveBy { entity, offset } => {
                    format!("move '{entity}' by {}", axis_label(*offset))
                }
                ActionSpec::SetMaterial { material, .. } => format!("change material '{material}'"),
            };
            out.push((e.frame, text));
        }
        out.sort_by_key(|(f, _)| *f);
        out
    }
}
