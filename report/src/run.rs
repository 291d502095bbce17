//! Reading a run folder: the manifest (frames.csv is read by `metrics::frames_csv`).

use std::path::{Path, PathBuf};

use anyhow::Context;
use metrics::Region;
use metrics::frames_csv::Frames;
use serde::Deserialize;

#[derive(Clone, Debug, Deserialize)]
pub struct Event {
    pub frame: u32,
    #[serde(default)]
    pub label: String,
}

#[derive(Clone, Debug, Default, Deserialize)]
pub struct ReferenceInfo {
    #[serde(default)]
    pub spp: Option<u32>,
    #[serde(default)]
    pub frames: Vec<u32>,
}

/// One method's entry of the manifest's `settings.methods`, as far as the report reads it.
#[derive(Clone, Debug, Default, Deserialize)]
pub struct MethodSettings {
    #[serde(default)]
    pub label: String,
    /// Effective temporal window, frames (frame::temporal_window); absent in runs
    /// before temporal windows were recorded and for methods that state none.
    #[serde(default)]
    pub temporal_window: Option<f64>,
}

#[derive(Clone, Debug, Default, Deserialize)]
pub struct Settings {
    #[serde(default)]
    pub methods: Vec<MethodSettings>,
}

/// One method's device memory (the manifest's `memory.methods`).
#[derive(Clone, Debug, Default, Deserialize, serde::Serialize)]
pub struct MethodMemory {
    #[serde(default)]
    pub label: String,
    #[serde(default)]
    pub device_bytes: Option<i64>,
}

/// The run's memory (the manifest's `memory`, written by playback::memory after the frames);
/// absent in older runs and in runs that did not finish.
#[derive(Clone, Debug, Default, Deserialize, serde::Serialize)]
pub struct Memory {
    #[serde(default)]
    pub scene_device_bytes: Option<i64>,
    #[serde(default)]
    pub methods: Vec<MethodMemory>,
    #[serde(default)]
    pub device_bytes_built: Option<u64>,
    #[serde(default)]
    pub device_bytes_end: Option<u64>,
    #[serde(default)]
    pub device_reserved_bytes_end: Option<u64>,
    #[serde(default)]
    pub peak_resident_bytes: Option<u64>,
    #[serde(default)]
    pub resident_bytes_end: Option<u64>,
}

/// The fields of manifest.json the report uses; the whole JSON is kept in `raw`.
#[derive(Clone, Debug, Deserialize)]
pub struct Manifest {
    #[serde(default)]
    pub scenario: String,
    #[serde(default)]
    pub methods: Vec<String>,
    #[serde(default)]
    pub frames: Option<u32>,
    #[serde(default)]
    pub resolution: Option<[u32; 2]>,
    #[serde(default)]
    pub reference: ReferenceInfo,
    #[serde(default)]
    pub events: Vec<Event>,
    #[serde(default)]
    pub regions: Vec<Region>,
    #[serde(default)]
    pub settings: Settings,
    #[serde(default)]
    pub memory: Option<Memory>,
    #[serde(skip)]
    pub raw: serde_json::Value,
}

impl Manifest {
    pub fn load(run_dir: &Path) -> anyhow::Result<Self> {
        let path = run_dir.join("manifest.json");
        let text = std::fs::read_to_string(&path)
            .with_context(|| format!("cannot read {}", path.display()))?;
        let raw: serde_json::Value = serde_json::from_str(&text)
            .with_context(|| format!("{}: not valid JSON", path.display()))?;
        let mut m: Manifest = serde_json::from_value(raw.clone()).with_context(|| {
            format!(
                "{}: expected the run manifest (scenario, methods, events, regions, ...)",
                path.display()
            )
        })?;
        m.raw = raw;
        m.events = merge_events(m.events);
        Ok(m)
    }

    /// Frames of the run: those in frames.csv, or the manifest's count if larger.
    pub fn frame_count(&self, frames: &Frames) -> u32 {
        frames.rows.iter().map(|r| r.frame + 1).max().unwrap_or(0).max(self.frames.unwrap_or(0))
    }
}

/// Events sorted by frame, those of one frame merged into one ("a + b"): windows, chart markers
/// and slider marks are per frame.
pub fn merge_events(mut events: Vec<Event>) -> Vec<Event> {
    events.sort_by_key(|e| e.frame);
    let mut out: Vec<Event> = Vec::new();
    for e in events {
        match out.last_mut() {
            Some(last) if last.frame == e.frame => {
                last.label = format!("{} + {}", last.label, e.label)
            }
            _ => out.push(e),
        }
    }
    out
}

/// The folder of a method's motion vectors, `frames/METHOD/motion/` (as frame::run_folder).
pub const MOTION: &str = "motion";

pub fn frame_file(run_dir: &Path, method: Option<&str>, frame: u32, ext: &str) -> PathBuf {
    match method {
        Some(m) => run_dir.join("frames").join(m).join(format!("{frame:04}.{ext}")),
        None => run_dir.join("reference").join(format!("{frame:04}.{ext}")),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn events_of_one_frame_become_one() {
        let ev = |frame, label: &str| Event { frame, label: label.into() };
        let merged = merge_events(vec![ev(20, "rotate"), ev(5, "flash"), ev(20, "move")]);
        let got: Vec<(u32, &str)> = merged.iter().map(|e| (e.frame, e.label.as_str())).collect();
        assert_eq!(got, [(5, "flash"), (20, "rotate + move")]);
    }
}
