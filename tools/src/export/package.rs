//! An exported package read back: its manifest and a check that every frame it promises is there
//! (what `flicker measure --scenario DIR` relies on).

use std::path::{Path, PathBuf};

use anyhow::{Context, Result, bail};
use serde_json::Value;

/// `format` of an export's manifest.json.
pub const FORMAT: &str = "flicker-export";
pub const VERSION: u32 = 1;
pub const MANIFEST: &str = "manifest.json";
pub const GLB: &str = "scene.glb";
pub const SCENARIO: &str = "scenario.ron";
pub const REFERENCE: &str = "reference";
/// The denoiser inputs, one folder each under `inputs/`.
pub const INPUTS: &[&str] = &["radiance", "albedo", "normal", "depth", "motion", "emission"];

/// What `flicker measure` takes from a package.
#[derive(Clone, Debug, PartialEq)]
pub struct Package {
    pub dir: PathBuf,
    pub frames: u32,
    pub fps: f64,
    /// (frame, label) of each event.
    pub events: Vec<(u32, String)>,
    pub cvvdp: metrics::CvvdpSettings,
    pub smape_epsilon: f32,
    /// The reference frames' folder.
    pub reference: PathBuf,
}

impl Package {
    pub fn read_manifest(dir: &Path) -> Result<Value> {
        let path = dir.join(MANIFEST);
        let text = std::fs::read_to_string(&path)
            .with_context(|| format!("{}: cannot read", path.display()))?;
        let v: Value =
            serde_json::from_str(&text).with_context(|| format!("{}: not JSON", path.display()))?;
        if v["format"] != FORMAT {
            bail!(
                "{}: format {}; expected \"{FORMAT}\" (a `flicker export` package)",
                path.display(),
                v["format"]
            );
        }
        Ok(v)
    }

    /// Reads the manifest and checks that every reference frame 0..frames is there.
    pub fn read(dir: &Path) -> Result<Package> {
        let v = Self::read_manifest(dir)?;
        let path = dir.join(MANIFEST);
        let field = |key: &str| {
            v.get(key)
                .filter(|x| !x.is_null())
                .with_context(|| format!("{}: no \"{key}\"", path.display()))
        };
        let frames = field("frames")?.as_u64().context("frames: expected a count")? as u32;
        let fps = field("fps")?.as_f64().context("fps: expected a number")?;
        let events = field("events")?
            .as_array()
            .context("events: expected a list")?
            .iter()
            .map(|e| {
                Ok((
                    e["frame"].as_u64().context("an event without a frame")? as u32,
                    e["label"].as_str().unwrap_or("").to_string(),
                ))
            })
            .collect::<Result<Vec<_>>>()
            .with_context(|| format!("{}: events", path.display()))?;
        let cvvdp: metrics::CvvdpSettings = serde_json::from_value(field("cvvdp")?.clone())
            .with_context(|| format!("{}: cvvdp", path.display()))?;
        let smape_epsilon = v["smape_epsilon"].as_f64().unwrap_or(0.01) as f32;
        let reference = field("reference")
            .with_context(|| "the package was exported with --scene-only: it has no references")?;
        let reference = dir.join(reference["dir"].as_str().unwrap_or(REFERENCE));
        for k in 0..frames {
            let f = reference.join(format!("{k:04}.exr"));
            if !f.is_file() {
                bail!(
                    "{}: frame {k} is missing (the manifest {} promises frames 0..{frames})",
                    f.display(),
                    path.display()
                );
            }
        }
        Ok(Package { dir: dir.to_path_buf(), frames, fps, events, cvvdp, smape_epsilon, reference })
    }
}
