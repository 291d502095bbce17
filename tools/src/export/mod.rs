//! `flicker export SCENARIO --out DIR`: a scenario as a self-contained package that any renderer
//! can play and `flicker measure --scenario DIR` measures against:
//!
//! ```text
//! DIR/manifest.json            frame rate, frames, resolution, events, display, what is where
//! DIR/scene.glb                the scene and everything that moves (glb.rs)
//! DIR/scenario.ron             the package played by flicker itself (scene: Gltf("scene.glb"))
//! DIR/CONVENTIONS.md           coordinate system, units, motion vectors, what radiance means
//! DIR/frames/NNNN.json         per frame: camera matrices, jitter, lights, events (record.rs)
//! DIR/reference/NNNN.exr       path-traced reference (linear radiance, scan-line EXR)
//! DIR/inputs/KIND/NNNN.exr     a denoiser's inputs: radiance (1 spp), albedo, normal, depth,
//!                              motion, emission
//! ```
//!
//! The frames are simulated once (sim, no GPU) for the glTF and the records; the references and
//! inputs are rendered by playing the scenario with `PathTracing(spp: 1, gbuffer: true)` and a
//! reference at every frame (playback::play), then re-encoded into the package.

pub mod glb;
pub mod package;
pub mod record;

use std::path::{Path, PathBuf};

use anyhow::{Context, Result, bail};
use frame::run_folder::RunFolder;
use playback::play::{Overrides, RunOptions, RunSpec};
use serde_json::json;
use sim::{MethodEntry, ReferenceFrames, Scenario, Simulation};

pub use package::{INPUTS, Package};

/// The conventions page, written into every package (docs/export.md has the same text).
pub const CONVENTIONS: &str = include_str!("CONVENTIONS.md");

/// What to export and where.
#[derive(Clone, Debug, Default)]
pub struct ExportOptions {
    pub scenario: PathBuf,
    pub out: PathBuf,
    /// frames, resolution, seed and (for the references) spp replace the scenario's.
    pub overrides: Overrides,
    /// Reference samples per pixel [default: the scenario's reference spp].
    pub reference_spp: Option<u32>,
    pub cache_dir: Option<PathBuf>,
    pub progress: bool,
    /// Write the glTF, the records and the manifest only (no references, no inputs).
    pub scene_only: bool,
}

/// The scenario's scene at every recorded frame.
pub fn simulate(scenario: &Scenario) -> Result<Vec<scene::SceneDesc>> {
    let mut sim = Simulation::new(scenario)?;
    let mut frames = Vec::with_capacity(scenario.frames as usize);
    for step in 0..scenario.warmup_frames + scenario.frames {
        if step > 0 {
            sim.step();
        }
        if step >= scenario.warmup_frames {
            let s = sim.scene();
            frames.push(if frames.is_empty() {
                s.clone()
            } else {
                scene::SceneDesc { meshes: vec![], textures: vec![], ..s.clone() }
            });
        }
    }
    Ok(frames)
}

/// The package's own scenario: the glb, played with its recorded frames.
/// `environment`: the scene's (a built-in scene's own, or the scenario's).
fn package_scenario(s: &Scenario, environment: glam::Vec3, reference_spp: u32) -> String {
    let e = environment;
    format!(
        "// Written by `flicker export` from {origin}: this package's scene.glb played by flicker.\n\
         (\n    name: \"{name}_export\",\n    scene: Gltf(\"scene.glb\"),\n    environment: ({}, {}, {}),\n    resolution: ({}, {}),\n    frames: {},\n    time_step: {},\n    seed: {},\n    max_depth: {},\n    smape_epsilon: {},\n    cvvdp: (display: \"{}\", exposure: {}),\n    reference: (spp: {reference_spp}, frames: Every(1)),\n    methods: [PathTracing(spp: 1)],\n)\n",
        e.x,
        e.y,
        e.z,
        s.resolution.0,
        s.resolution.1,
        s.frames,
        ron_f32(s.time_step),
        s.seed,
        s.max_depth,
        ron_f32(s.smape_epsilon),
        s.cvvdp.display,
        ron_f32(s.cvvdp.exposure),
        origin = s.origin.display(),
        name = s.name,
    )
}

/// A float as RON reads it back exactly (Rust's shortest round-trip form, always with a dot).
fn ron_f32(v: f32) -> String {
    let s = format!("{v:?}");
    if s.contains(['.', 'e', 'E']) { s } else { format!("{s}.0") }
}

/// Refuses a non-empty folder that is not an earlier package (so a typo never deletes files).
fn prepare(out: &Path) -> Result<()> {
    if out.exists() {
        let empty = std::fs::read_dir(out)
            .with_context(|| format!("reading {}", out.display()))?
            .next()
            .is_none();
        if !empty {
            if Package::read_manifest(out).is_err() {
                bail!(
                    "{}: not empty and holds no earlier export (no manifest.json of format {}); choose another --out",
                    out.display(),
                    package::FORMAT
                );
            }
            std::fs::remove_dir_all(out).with_context(|| format!("removing {}", out.display()))?;
        }
    }
    std::fs::create_dir_all(out).with_context(|| format!("creating {}", out.display()))
}

/// Writes the package; returns its manifest's path.
pub fn export(opts: &ExportOptions) -> Result<PathBuf> {
    let spec = RunSpec::load(&opts.scenario, &opts.overrides)?;
    let scenario = spec.scenario;
    if !scenario.media.is_empty() {
        bail!(
            "{}: medium '{}': participating media are not exported; expected a scenario without media",
            scenario.origin.display(),
            scenario.media[0].name
        );
    }
    let reference_spp = opts.reference_spp.unwrap_or(scenario.reference.spp).max(1);
    let frames = simulate(&scenario)?;
    let (w, h) = scenario.resolution;
    let glb = glb::write(&frames, scenario.time_step, w as f32 / h as f32, &scenario.name)
        .with_context(|| format!("{}: exporting the scene", scenario.origin.display()))?;
    let events = playback::manifest::recorded_events(&scenario);

    prepare(&opts.out)?;
    let out = &opts.out;
    frame::output::write_atomic(&out.join(package::GLB), |f| Ok(f.write_all(&glb)?))?;
    frame::output::write_text(
        &out.join(package::SCENARIO),
        &package_scenario(&scenario, frames[0].environment, reference_spp),
    )?;
    frame::output::write_text(&out.join("CONVENTIONS.md"), CONVENTIONS)?;
    for (k, f) in frames.iter().enumerate() {
        let k = k as u32;
        let labels: Vec<&str> =
            events.iter().filter(|(e, _)| *e == k).map(|(_, l)| l.as_str()).collect();
        let rec = record::frame(k, scenario.time_step, &frames[0], f, (w, h), &labels);
        frame::output::write_json(&out.join("frames").join(format!("{k:04}.json")), &rec)?;
    }
    if !opts.scene_only {
        render(&scenario, reference_spp, opts)?;
    }
    let manifest = json!({
        "format": package::FORMAT,
        "version": package::VERSION,
        "scenario": scenario.name,
        "scenario_file": scenario.origin.display().to_string(),
        "flicker_version": env!("CARGO_PKG_VERSION"),
        "frames": scenario.frames,
        "fps": 1.0 / scenario.time_step as f64,
        "time_step": scenario.time_step,
        "resolution": [w, h],
        "seed": scenario.seed,
        "max_depth": scenario.max_depth,
        "events": events.iter().map(|(f, l)| json!({"frame": f, "label": l})).collect::<Vec<_>>(),
        "cvvdp": scenario.cvvdp,
        "smape_epsilon": scenario.smape_epsilon,
        "regions": scenario.regions.iter().map(|r| json!({"name": r.name, "x": r.x, "y": r.y, "width": r.width, "height": r.height})).collect::<Vec<_>>(),
        "scene": package::GLB,
        "flicker_scenario": package::SCENARIO,
        "records": "frames/NNNN.json",
        "reference": if opts.scene_only { json!(null) } else { json!({"dir": package::REFERENCE, "spp": reference_spp}) },
        "inputs": if opts.scene_only { json!(null) } else { json!({"dir": "inputs", "kinds": INPUTS, "spp": 1}) },
    });
    let path = out.join(package::MANIFEST);
    frame::output::write_json(&path, &manifest)?;
    Ok(path)
}

/// Renders the references and the denoiser inputs into the package.
fn render(scenario: &Scenario, reference_spp: u32, opts: &ExportOptions) -> Result<()> {
    let out = &opts.out;
    let scratch = out.join(".render");
    let mut s = scenario.clone();
    s.methods = vec![MethodEntry::new("PathTracing(spp: 1, gbuffer: true)")];
    s.reference.frames = ReferenceFrames::Every(1);
    s.reference.spp = reference_spp;
    s.output = scratch.clone();
    let spec = RunSpec::from_scenario(s, &Overrides::default())?;
    let label = spec.methods[0].label();
    playback::play::run_spec(
        &spec,
        &RunOptions {
            scenario: opts.scenario.clone(),
            overrides: opts.overrides.clone(),
            cache_dir: opts.cache_dir.clone(),
            progress: opts.progress,
        },
    )?;
    let run = RunFolder::new(&scratch);
    for k in 0..scenario.frames {
        let name = format!("{k:04}.exr");
        copy_exr(&run.reference(k, "exr"), &out.join(package::REFERENCE).join(&name))?;
        for kind in INPUTS {
            let from = match *kind {
                "radiance" => run.frame(&label, k, "exr"),
                other => run.method_image(&label, other, k, "exr"),
            };
            copy_exr(&from, &out.join("inputs").join(kind).join(&name))?;
        }
    }
    std::fs::remove_dir_all(&scratch).with_context(|| format!("removing {}", scratch.display()))
}

/// Re-encodes an EXR as RGB float, scan-line, ZIP (what NVIDIA's flip reads).
fn copy_exr(from: &Path, to: &Path) -> Result<()> {
    let (w, h, rgba) = frame::output::read_exr(from)?;
    let image = metrics::Image {
        width: w,
        height: h,
        rgb: rgba.iter().map(|p| [p[0], p[1], p[2]]).collect(),
    };
    if let Some(dir) = to.parent() {
        std::fs::create_dir_all(dir).with_context(|| format!("creating {}", dir.display()))?;
    }
    metrics::write_exr(&image, to)
}

#[cfg(test)]
mod tests {
    #[test]
    fn floats_read_back_as_ron_floats() {
        assert_eq!(super::ron_f32(1.0), "1.0");
        assert_eq!(super::ron_f32(1.0 / 30.0), "0.033333335");
    }
}
