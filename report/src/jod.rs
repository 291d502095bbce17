//! ColorVideoVDP's JOD of each method over each summary window: the method's recorded frames
//! against the reference frames of that window, read back from the run folder and played as a
//! video at the run's frame rate (metrics::cvvdp). Needs a reference at evenly spaced frames; with
//! one every n-th frame the video plays at fps / n, which hides flicker faster than that.

use std::collections::BTreeMap;
use std::path::Path;

use anyhow::Context;
use metrics::{CvvdpSettings, Image, load_image};

use crate::run::{Manifest, frame_file};
use crate::window::Window;

/// The run's JOD settings (manifest `settings.cvvdp`), the metric's defaults where absent.
pub fn settings(manifest: &Manifest) -> anyhow::Result<CvvdpSettings> {
    match manifest.raw.get("settings").and_then(|s| s.get("cvvdp")) {
        None => Ok(CvvdpSettings::default()),
        Some(v) => Ok(serde_json::from_value(v.clone())?),
    }
}

/// The run's frame rate (manifest `settings.time_step`; 30 fps where absent). A scenario's step
/// is an f32, so the rate is taken in f32: a run and its frames measured at `--fps 30` then play
/// at the same rate.
pub fn fps(manifest: &Manifest) -> f32 {
    let step =
        manifest.raw.get("settings").and_then(|s| s.get("time_step")).and_then(|v| v.as_f64());
    step.map(|t| t as f32).filter(|&t| t > 0.0).map_or(30.0, |t| 1.0 / t)
}

/// Frames of `window` with both a reference and a frame of `method` on disk, and their spacing;
/// `None` when they are not evenly spaced (a video needs a constant frame rate).
fn frames_of(run_dir: &Path, method: &str, window: &Window) -> Option<(Vec<u32>, u32)> {
    let frames: Vec<u32> = (window.first..=window.last)
        .filter(|&f| {
            frame_file(run_dir, None, f, "exr").exists()
                && frame_file(run_dir, Some(method), f, "exr").exists()
        })
        .collect();
    let stride = match frames.as_slice() {
        [] => return None,
        [_] => 1,
        [a, b, ..] => b - a,
    };
    frames.windows(2).all(|w| w[1] - w[0] == stride).then_some((frames, stride))
}

/// The JOD distortion map of a method's frame (`1 - JOD_pixel / 10`, in R, G and B).
pub fn map_file(run_dir: &Path, method: &str, frame: u32) -> std::path::PathBuf {
    run_dir.join("frames").join(method).join(MAP).join(format!("{frame:04}.exr"))
}

/// The folder of a method's JOD maps, `frames/METHOD/jod/`.
pub const MAP: &str = "jod";

/// What JOD found for one method: window name -> JOD, and why a window has none.
#[derive(Clone, Debug, Default)]
pub struct MethodJod {
    pub by_window: BTreeMap<String, f64>,
    pub notes: Vec<String>,
}

/// JOD per method and window. Windows without evenly spaced reference frames get no value; a
/// frame the metric refuses (non-finite pixels, smaller than 4x4) gets a note, not an error, so
/// that the rest of the report is still written.
pub fn per_window(
    run_dir: &Path,
    manifest: &Manifest,
    methods: &[String],
    windows: &[Window],
) -> anyhow::Result<BTreeMap<String, MethodJod>> {
    let settings = settings(manifest)?;
    let mut out = BTreeMap::new();
    if !settings.enabled {
        return Ok(out);
    }
    let fps = fps(manifest);
    let mut references: BTreeMap<u32, Image> = BTreeMap::new();
    for method in methods {
        let mut m = MethodJod::default();
        let mut tests: BTreeMap<u32, Image> = BTreeMap::new();
        for w in windows {
            let Some((frames, stride)) = frames_of(run_dir, method, w) else { continue };
            for &f in &frames {
                if let std::collections::btree_map::Entry::Vacant(e) = references.entry(f) {
                    e.insert(load_image(frame_file(run_dir, None, f, "exr"))?);
                }
                if let std::collections::btree_map::Entry::Vacant(e) = tests.entry(f) {
                    e.insert(load_image(frame_file(run_dir, Some(method), f, "exr"))?);
                }
            }
            let reference: Vec<Image> = frames.iter().map(|f| references[f].clone()).collect();
            let test: Vec<Image> = frames.iter().map(|f| tests[f].clone()).collect();
            // The whole run's maps are the viewer's; a window's would only repeat parts of them.
            let maps = w.name == "overall";
            match metrics::jod(&reference, &test, fps / stride as f32, &settings, maps) {
                Ok(r) => {
                    m.by_window.insert(w.name.clone(), r.jod);
                    if r.maps.is_some() {
                        let dir = map_file(run_dir, method, 0);
                        let dir = dir.parent().unwrap_or(run_dir);
                        std::fs::create_dir_all(dir)
                            .with_context(|| format!("cannot create {}", dir.display()))?;
                    }
                    for (map, &f) in r.maps.iter().flatten().zip(&frames) {
                        let (width, height) = (reference[0].width, reference[0].height);
                        let img = Image::new(width, height, map.iter().map(|&v| [v; 3]).collect());
                        metrics::write_exr(&img, map_file(run_dir, method, f))?;
                    }
                }
                Err(e) => m.notes.push(format!("{}: {e:#}", w.name)),
            }
        }
        out.insert(method.clone(), m);
    }
    Ok(out)
}

/// JOD of `method` over frames `first..=last` of a run folder (a suite's window); `None` where
/// those frames have no evenly spaced references or JOD is switched off.
pub fn of_frames(
    run_dir: &Path,
    method: &str,
    first: u32,
    last: u32,
) -> anyhow::Result<Option<f64>> {
    let manifest = Manifest::load(run_dir)?;
    let window = Window { name: "frames".into(), first, last, event: None };
    let jod = per_window(run_dir, &manifest, &[method.to_string()], &[window])?;
    Ok(jod.get(method).and_then(|m| m.by_window.get("frames").copied()))
}
