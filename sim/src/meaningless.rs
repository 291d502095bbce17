//! Values that parse but make a run meaningless: a view that sees nothing (field of view 0 or
//! 180 degrees and more, a camera looking along its up vector or at its own position), a mesh
//! scaled to zero extent, events and references outside the run, references that are asked
//! for but never rendered, waveforms that never flash. Each is refused at the file, line and
//! column of the value with what was expected.
//!
//! Positions reuse what the parser gives the `methods` list: the lists are read a second time
//! as raw RON entries (`scenario::raw_entries`, each with its line and column), and a field is
//! found inside its entry's text (`MethodEntry::position_in_file`).

use std::path::Path;

use glam::Vec3;
use ron::value::RawValue;
use serde::Deserialize;

use crate::scenario::{
    ActionSpec, AnimationSpec, MethodEntry, ReferenceFrames, Scenario, ScenarioError, WaveformSpec,
    line_col, raw_entries,
};

/// The parts of the file whose entries need a place; every other field is skipped.
#[derive(Deserialize, Default)]
#[serde(rename = "Scenario")]
struct Shadow {
    #[serde(default)]
    camera: Option<Box<RawValue>>,
    #[serde(default)]
    reference: Option<Box<RawValue>>,
    #[serde(default)]
    animations: Vec<Box<RawValue>>,
    #[serde(default)]
    events: Vec<Box<RawValue>>,
}

/// Where each entry of the scenario's lists starts, to point errors inside them.
struct Places<'a> {
    text: &'a str,
    origin: &'a Path,
    camera: Option<MethodEntry>,
    reference: Option<MethodEntry>,
    animations: Vec<MethodEntry>,
    events: Vec<MethodEntry>,
}

impl<'a> Places<'a> {
    fn new(text: &'a str, origin: &'a Path) -> Self {
        let options = ron::Options::default()
            .with_default_extension(ron::extensions::Extensions::IMPLICIT_SOME);
        // The file parsed once already; should this fail, errors point at top-level keys.
        let shadow: Shadow = options.from_str(text).unwrap_or_default();
        let one = |key: &str, raw: &Option<Box<RawValue>>| {
            raw.as_ref().and_then(|r| raw_entries(text, key, std::slice::from_ref(r)).pop())
        };
        Places {
            text,
            origin,
            camera: one("camera", &shadow.camera),
            reference: one("reference", &shadow.reference),
            animations: raw_entries(text, "animations", &shadow.animations),
            events: raw_entries(text, "events", &shadow.events),
        }
    }

    /// The first top-level `key:` of the file.
    fn key(&self, key: &str) -> Option<(usize, usize)> {
        field_at(self.text, key, 0).map(|at| line_col(self.text, at))
    }

    /// The `nth` (0-based) `field:` inside `entry`, else the entry itself.
    fn inside(entry: Option<&MethodEntry>, field: &str, nth: usize) -> Option<(usize, usize)> {
        let entry = entry?;
        Some(match field_at(&entry.text, field, nth) {
            Some(at) => {
                let (line, column) = line_col(&entry.text, at);
                entry.position_in_file(line, column)
            }
            None => (entry.line, entry.column),
        })
    }

    fn error(&self, position: Option<(usize, usize)>, message: String) -> ScenarioError {
        ScenarioError { file: self.origin.to_path_buf(), position, message }
    }
}

/// Byte offset of the `nth` occurrence of `field` used as a key (`field:`), as a whole word.
fn field_at(text: &str, field: &str, nth: usize) -> Option<usize> {
    let bytes = text.as_bytes();
    let word = |b: u8| b.is_ascii_alphanumeric() || b == b'_';
    text.match_indices(field)
        .filter(|(at, _)| {
            let end = at + field.len();
            (*at == 0 || !word(bytes[at - 1]))
                && text[end..].trim_start().starts_with(':')
                && !text[end..].trim_start().starts_with("::")
        })
        .nth(nth)
        .map(|(at, _)| at)
}

fn fov_ok(degrees: f32) -> bool {
    degrees > 0.0 && degrees < 180.0
}

/// Why a view from `position` towards `target` with `up` sees nothing, if it does not.
fn view_problem(position: Vec3, target: Vec3, up: Vec3) -> Option<String> {
    let forward = target - position;
    if forward.length() <= 1e-6 * position.length().max(1.0) {
        return Some(format!(
            "target {} is the camera's position; expected a target away from the camera",
            v3(target)
        ));
    }
    if up.length() <= 1e-12 {
        return Some("up is (0, 0, 0); expected a non-zero up vector".into());
    }
    // Looking along `up` leaves the image's orientation undefined (a NaN basis).
    if forward.normalize().cross(up.normalize()).length() < 1e-4 {
        return Some(format!(
            "the camera looks along its up vector {} (towards {}); expected an up vector not parallel to the view direction",
            v3(up),
            v3(target)
        ));
    }
    None
}

fn v3(v: Vec3) -> String {
    format!("({}, {}, {})", v.x, v.y, v.z)
}

/// Refuses a scenario whose values parse but would make the run meaningless.
pub(crate) fn check(s: &Scenario) -> Result<(), ScenarioError> {
    let p = Places::new(&s.source, &s.origin);
    let total = s.warmup_frames.saturating_add(s.frames);
    let run_frames = || {
        format!(
            "the run simulates frames 0 to {} ({} warm-up + {} recorded)",
            total - 1,
            s.warmup_frames,
            s.frames
        )
    };

    if let Some(c) = &s.camera {
        let at = |field: &str| Places::inside(p.camera.as_ref(), field, 0).or(p.key("camera"));
        if !fov_ok(c.vfov_degrees) {
            return Err(p.error(
                at("vfov_degrees"),
                format!(
                    "camera: vfov_degrees {}; expected a vertical field of view above 0 and below 180 degrees",
                    c.vfov_degrees
                ),
            ));
        }
        if let Some(problem) = view_problem(c.position, c.target, c.up) {
            let field = if problem.starts_with("target") { "target" } else { "up" };
            return Err(p.error(at(field), format!("camera: {problem}")));
        }
    }

    if s.max_depth == 0 {
        return Err(p.error(
            p.key("max_depth"),
            "max_depth: 0 ends every path before it reaches a light; expected at least 1 (1 = direct lighting)".into(),
        ));
    }
    if s.smape_epsilon <= 0.0 {
        return Err(p.error(
            p.key("smape_epsilon"),
            format!(
                "smape_epsilon {}; expected a small positive number (0.01 in the paper), else black pixels divide 0 by 0",
                s.smape_epsilon
            ),
        ));
    }
    if let Some(env) = s.environment
        && env.min_element() < 0.0
    {
        return Err(p.error(
            p.key("environment"),
            format!("environment {}; expected radiance >= 0 in each channel", v3(env)),
        ));
    }

    check_reference(s, &p)?;

    for (i, a) in s.animations.iter().enumerate() {
        let entry = p.animations.get(i);
        let at =
            |field: &str, nth: usize| Places::inside(entry, field, nth).or(p.key("animations"));
        match a {
            AnimationSpec::RotateOnce { entity, frame, .. } if *frame >= total => {
                return Err(p.error(
                    at("frame", 0),
                    format!(
                        "RotateOnce of '{entity}' at frame {frame} never happens: {}; expected a frame below {total}",
                        run_frames()
                    ),
                ));
            }
            AnimationSpec::Flash { entity, waveform } => {
                let problem = match *waveform {
                    WaveformSpec::Sine { frequency } if frequency <= 0.0 => Some((
                        "frequency",
                        format!("frequency {frequency} never flashes; expected a frequency > 0 Hz"),
                    )),
                    WaveformSpec::Strobe { probability }
                        if !(probability > 0.0 && probability <= 1.0) =>
                    {
                        Some((
                            "probability",
                            format!(
                                "probability {probability}; expected a probability above 0 and at most 1"
                            ),
                        ))
                    }
                    _ => None,
                };
                if let Some((field, message)) = problem {
                    return Err(p.error(at(field, 0), format!("Flash of '{entity}': {message}")));
                }
            }
            AnimationSpec::Boids { prototype, count, .. } if *count == 0 => {
                return Err(p.error(
                    at("count", 0),
                    format!("Boids of '{prototype}': count 0 flocks nothing; expected at least 1"),
                ));
            }
            AnimationSpec::Keyframes { entity, keys, .. } => {
                for (k, key) in keys.iter().enumerate() {
                    if let Some(r) = &key.rotation
                        && r.axis.length() <= 1e-12
                    {
                        return Err(p.error(
                            at("frame", k),
                            format!(
                                "key {k} of '{entity}': rotation axis (0, 0, 0); expected a non-zero axis"
                            ),
                        ));
                    }
                    if let Some(scale) = key.scale
                        && scale.abs().min_element() == 0.0
                    {
                        return Err(p.error(
                            at("frame", k),
                            format!(
                                "key {k} of '{entity}': scale {} flattens it to zero extent; expected a non-zero scale on every axis",
                                v3(scale)
                            ),
                        ));
                    }
                }
            }
            AnimationSpec::CameraPath { keys, .. } => {
                for (k, key) in keys.iter().enumerate() {
                    if let Some(v) = key.vfov_degrees
                        && !fov_ok(v)
                    {
                        return Err(p.error(
                            at("frame", k),
                            format!(
                                "camera path key {k}: vfov_degrees {v}; expected a vertical field of view above 0 and below 180 degrees"
                            ),
                        ));
                    }
                    // Camera paths keep the world's up, +y.
                    if let Some(problem) = view_problem(key.position, key.target, Vec3::Y) {
                        return Err(
                            p.error(at("frame", k), format!("camera path key {k}: {problem}"))
                        );
                    }
                }
            }
            _ => {}
        }
    }

    for (i, e) in s.events.iter().enumerate() {
        let entry = p.events.get(i);
        let at = |field: &str| Places::inside(entry, field, 0).or(p.key("events"));
        if e.frame >= total {
            return Err(p.error(
                at("frame"),
                format!(
                    "event at frame {} never happens: {}; expected a frame below {total}",
                    e.frame,
                    run_frames()
                ),
            ));
        }
        if let ActionSpec::SetMaterial { material, base_color, emission, roughness, metallic } =
            &e.action
        {
            let unit = [("roughness", roughness), ("metallic", metallic)];
            if let Some((field, v)) = unit
                .iter()
                .find_map(|(f, v)| v.filter(|v| !(0.0..=1.0).contains(v)).map(|v| (f, v)))
            {
                return Err(p.error(
                    at(field),
                    format!("SetMaterial '{material}': {field} {v}; expected a value from 0 to 1"),
                ));
            }
            let colours = [("base_color", base_color), ("emission", emission)];
            if let Some((field, v)) = colours
                .iter()
                .find_map(|(f, v)| v.filter(|v| v.min_element() < 0.0).map(|v| (f, v)))
            {
                return Err(p.error(
                    at(field),
                    format!(
                        "SetMaterial '{material}': {field} {}; expected values >= 0 in each channel",
                        v3(v)
                    ),
                ));
            }
        }
    }

    for (i, r) in s.regions.iter().enumerate() {
        if s.regions[..i].iter().any(|o| o.name == r.name) {
            return Err(p.error(
                crate::scenario::find_quoted(&s.source, &r.name).or(p.key("regions")),
                format!("two regions named '{}'; expected distinct names ", r.name),
            ));
        }
    }
    Ok(())
}

/// A reference that is asked for must be rendered on a frame of the run.
fn check_reference(s: &Scenario, p: &Places) -> Result<(), ScenarioError> {
    let r = &s.reference;
    let at = |field: &str| Places::inside(p.reference.as_ref(), field, 0).or(p.key("reference"));
    let asks = match &r.frames {
        ReferenceFrames::None => false,
        ReferenceFrames::List(list) => !list.is_empty(),
        ReferenceFrames::Every(_) => true,
    };
    if asks && r.spp == 0 {
        return Err(p.error(
            at("spp"),
            "reference: spp 0 renders no reference, but frames asks for some; expected spp >= 1 (or frames: None)".into(),
        ));
    }
    match &r.frames {
        ReferenceFrames::Every(0) => Err(p.error(
            at("frames"),
            "reference: Every(0) names no frame; expected Every(n) with n >= 1 (or None)".into(),
        )),
        ReferenceFrames::List(list) => match list.iter().find(|f| **f >= s.frames) {
            Some(f) => Err(p.error(
                at("frames"),
                format!(
                    "reference frame {f} is outside the run's {} recorded frames; expected recorded frames 0 to {}",
                    s.frames,
                    s.frames - 1
                ),
            )),
            None => Ok(()),
        },
        _ => Ok(()),
    }
}

/// Position of the first top-level `key:` of a scenario's text.
pub(crate) fn key_position(text: &str, key: &str) -> Option<(usize, usize)> {
    field_at(text, key, 0).map(|at| line_col(text, at))
}

/// Why every frame of the run would be black, if it would: no light with power, no emissive
/// material, a black environment, no emitting medium and no event that lights anything. The
/// lights are as authored (`lights`), so one that flashes or is toggled off at frame 0 counts.
pub(crate) fn nothing_emits<'a>(
    s: &Scenario,
    lights: impl IntoIterator<Item = &'a scene::Light>,
    scene: &scene::SceneDesc,
) -> Option<String> {
    use scene::Light;
    let power = |l: &Light| match *l {
        Light::Directional { irradiance, .. } => irradiance,
        Light::Point { intensity, .. } | Light::Spot { intensity, .. } => intensity,
    };
    let emits = |v: Vec3| v.max_element() > 0.0;
    let lit = lights.into_iter().any(|l| emits(power(l)))
        || scene.materials.iter().any(|m| emits(m.emission))
        || emits(scene.environment)
        || s.media.iter().any(|m| m.emission.is_some_and(emits))
        || s.events.iter().any(
            |e| matches!(e.action, ActionSpec::SetMaterial { emission: Some(v), .. } if emits(v)),
        );
    (!lit).then(|| {
        "nothing in the scene emits light (no light with power, no emissive material, a black environment), so every frame would be black and every metric meaningless; expected a light, an emissive material or environment: (r, g, b) above 0".to_string()
    })
}

/// Why the scene's geometry is degenerate, if it is: an instanced mesh with no triangle of
/// positive area, or an instance whose transform flattens its mesh to zero extent.
pub(crate) fn degenerate_geometry(scene: &scene::SceneDesc) -> Option<String> {
    let flat = |m: &scene::Mesh| {
        !m.indices.iter().any(|t| {
            let [a, b, c] = t.map(|i| m.positions.get(i as usize).copied().unwrap_or(Vec3::ZERO));
            (b - a).cross(c - a).length_squared() > 0.0
        })
    };
    for inst in &scene.instances {
        let Some(mesh) = scene.meshes.get(inst.mesh as usize) else { continue };
        if flat(mesh) {
            return Some(format!(
                "mesh '{}' has no triangle of positive area (zero extent); expected a mesh with a surface",
                mesh.name
            ));
        }
        if inst.transform.determinant() == 0.0 {
            return Some(format!(
                "an instance of mesh '{}' is scaled to zero extent; expected a non-zero scale on every axis",
                mesh.name
            ));
        }
    }
    None
}
