//! summary.json: per method, the mean of every frames.csv column over the run's named frame
//! windows (crate::window), and per method and window ColorVideoVDP's JOD of those frames as a
//! video (crate::jod).

use std::collections::BTreeMap;
use std::path::Path;

use metrics::frames_csv::Frames;
use serde::Serialize;

use crate::run::{Manifest, Memory};
use crate::window::{DEFAULT_WINDOW, Window, windows};

#[derive(Clone, Debug, Serialize)]
pub struct MethodSummary {
    pub method: String,
    /// window name -> column -> mean over the window's measured frames.
    pub means: BTreeMap<String, BTreeMap<String, f64>>,
    /// Effective temporal window, frames, from the manifest (absent where the run states none).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub temporal_window: Option<f64>,
    /// window name -> ColorVideoVDP's JOD of the window's frames as a video (crate::jod); higher
    /// is better, 10 = no visible difference from the reference.
    #[serde(skip_serializing_if = "BTreeMap::is_empty")]
    pub jod: BTreeMap<String, f64>,
    /// Why a window has no JOD (the metric refused its frames).
    #[serde(skip_serializing_if = "Vec::is_empty")]
    pub jod_notes: Vec<String>,
}

#[derive(Clone, Debug, Serialize)]
pub struct Summary {
    pub scenario: String,
    pub window_frames: u32,
    pub windows: Vec<Window>,
    pub methods: Vec<MethodSummary>,
    /// The run's memory, from the manifest.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub memory: Option<Memory>,
    /// The display and exposure JOD was computed for (absent when no JOD was computed).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub cvvdp: Option<metrics::CvvdpSettings>,
}

pub fn summarize(manifest: &Manifest, frames: &Frames, n: u32) -> Summary {
    let frame_count = manifest.frame_count(frames);
    let windows = windows(manifest, frame_count, n);
    let methods = frames
        .methods()
        .into_iter()
        .map(|method| {
            let rows: Vec<_> = frames.rows.iter().filter(|r| r.method == method).collect();
            let means = windows
                .iter()
                .map(|w| {
                    let in_window: Vec<_> =
                        rows.iter().filter(|r| r.frame >= w.first && r.frame <= w.last).collect();
                    let cols = frames
                        .columns
                        .iter()
                        .enumerate()
                        .filter_map(|(c, name)| {
                            let vals: Vec<f64> = in_window
                                .iter()
                                .filter_map(|r| r.values[c])
                                .filter(|v| v.is_finite())
                                .collect();
                            (!vals.is_empty()).then(|| {
                                (name.clone(), vals.iter().sum::<f64>() / vals.len() as f64)
                            })
                        })
                        .collect();
                    (w.name.clone(), cols)
                })
                .collect();
            let temporal_window = manifest
                .settings
                .methods
                .iter()
                .find(|m| m.label == method)
                .and_then(|m| m.temporal_window);
            MethodSummary {
                method,
                means,
                temporal_window,
                jod: BTreeMap::new(),
                jod_notes: Vec::new(),
            }
        })
        .collect();
    Summary {
        scenario: manifest.scenario.clone(),
        window_frames: n,
        windows,
        methods,
        memory: manifest.memory.clone(),
        cvvdp: None,
    }
}

/// Adds each method's JOD per window, computed from the frames on disk (crate::jod).
pub fn add_jod(summary: &mut Summary, run_dir: &Path, manifest: &Manifest) -> anyhow::Result<()> {
    let methods: Vec<String> = summary.methods.iter().map(|m| m.method.clone()).collect();
    let jod = crate::jod::per_window(run_dir, manifest, &methods, &summary.windows)?;
    for m in &mut summary.methods {
        if let Some(j) = jod.get(&m.method) {
            m.jod = j.by_window.clone();
            m.jod_notes = j.notes.clone();
        }
    }
    if summary.methods.iter().any(|m| !m.jod.is_empty() || !m.jod_notes.is_empty()) {
        summary.cvvdp = Some(crate::jod::settings(manifest)?);
    }
    Ok(())
}

/// The JOD that write_summary put in RUN/summary.json, added to a summary built again (the
/// report's), so that the frames are read back and scored once per rebuild.
pub fn add_jod_from_file(summary: &mut Summary, run_dir: &Path) {
    let Ok(text) = std::fs::read_to_string(run_dir.join("summary.json")) else { return };
    let Ok(v) = serde_json::from_str::<serde_json::Value>(&text) else { return };
    for m in &mut summary.methods {
        let saved =
            v["methods"].as_array().and_then(|a| a.iter().find(|s| s["method"] == m.method));
        if let Some(saved) = saved {
            m.jod = serde_json::from_value(saved["jod"].clone()).unwrap_or_default();
            m.jod_notes = serde_json::from_value(saved["jod_notes"].clone()).unwrap_or_default();
        }
    }
    summary.cvvdp = serde_json::from_value(v["cvvdp"].clone()).ok();
}

/// Writes RUN/summary.json with the default transient length.
pub fn write_summary(run_dir: &Path) -> anyhow::Result<()> {
    write_summary_with_window(run_dir, DEFAULT_WINDOW)
}

pub fn write_summary_with_window(run_dir: &Path, n: u32) -> anyhow::Result<()> {
    let manifest = Manifest::load(run_dir)?;
    let frames = Frames::load(run_dir)?;
    let mut summary = summarize(&manifest, &frames, n);
    add_jod(&mut summary, run_dir, &manifest)?;
    let path = run_dir.join("summary.json");
    metrics::atomic::write_bytes(&path, serde_json::to_string_pretty(&summary)?)
}

#[cfg(test)]
mod temporal_window_tests {
    use super::*;

    /// Each method's effective temporal window goes from the manifest into the
    /// summary and the summary table; runs that state none show no column.
    #[test]
    fn the_manifest_temporal_windows_reach_the_summary_table() {
        let frames = Frames::parse(
            "method,frame,flip\ntaa,0,0.2\nssc,0,0.1\npt,0,0.3\n",
            Path::new("frames.csv"),
        )
        .unwrap();
        let manifest: Manifest = serde_json::from_str(
            r#"{"scenario": "s", "methods": ["taa", "ssc", "pt"], "settings": {"methods": [
                {"label": "taa", "temporal_window": 19.0}, {"label": "ssc", "temporal_window": 76.0}, {"label": "pt"}]}}"#,
        )
        .unwrap();
        let summary = summarize(&manifest, &frames, DEFAULT_WINDOW);
        let windows: Vec<_> =
            summary.methods.iter().map(|m| (m.method.as_str(), m.temporal_window)).collect();
        assert_eq!(windows, [("taa", Some(19.0)), ("ssc", Some(76.0)), ("pt", None)]);
        let html = crate::table::html(&summary, &frames).into_string();
        assert!(html.contains("temporal window (frames)</th>"), "{html}");
        assert!(
            html.contains(">ssc</td><td>76.0</td>") && html.contains(">pt</td><td></td>"),
            "{html}"
        );
        let json = serde_json::to_value(&summary).unwrap();
        assert_eq!(json["methods"][1]["temporal_window"], 76.0);
        assert!(json["methods"][2].get("temporal_window").is_none());

        let old: Manifest =
            serde_json::from_str(r#"{"scenario": "s", "methods": ["taa", "ssc", "pt"]}"#).unwrap();
        let html =
            crate::table::html(&summarize(&old, &frames, DEFAULT_WINDOW), &frames).into_string();
        assert!(!html.contains("temporal window"), "{html}");
    }
}

#[cfg(test)]
mod memory_tests {
    use super::*;

    #[test]
    fn the_manifest_memory_reaches_the_summary_and_its_table() {
        let frames =
            Frames::parse("method,frame,flip\npt,0,0.3\n", Path::new("frames.csv")).unwrap();
        let manifest: Manifest = serde_json::from_str(
            r#"{"scenario": "s", "methods": ["pt"], "memory": {"scene_device_bytes": 2097152,
                "methods": [{"label": "pt", "device_bytes": 1048576}], "device_bytes_built": 3145728,
                "device_bytes_end": 3145728, "peak_resident_bytes": 104857600}}"#,
        )
        .unwrap();
        let summary = summarize(&manifest, &frames, DEFAULT_WINDOW);
        let json = serde_json::to_value(&summary).unwrap();
        assert_eq!(json["memory"]["methods"][0]["device_bytes"], 1048576);
        assert_eq!(json["memory"]["peak_resident_bytes"], 104857600);
        let html = crate::table::memory_html(summary.memory.as_ref().unwrap()).into_string();
        assert!(html.contains(">device: pt</td><td>1.00</td>"), "{html}");
        assert!(html.contains(">process: peak resident</td><td>100.00</td>"), "{html}");
        let old: Manifest =
            serde_json::from_str(r#"{"scenario": "s", "methods": ["pt"]}"#).unwrap();
        assert!(
            serde_json::to_value(summarize(&old, &frames, DEFAULT_WINDOW))
                .unwrap()
                .get("memory")
                .is_none()
        );
    }
}
