//! `manifest.json`: what was run, on what, with which settings — enough to reproduce a run.

use std::path::Path;

use anyhow::Result;
use render::gpu::Gpu;
use serde_json::{Value, json};
use crate::scenario::{Overrides, RunSpec};

pub fn build(spec: &RunSpec, scenario_file: &Path, gpu: &Gpu, overrides: &Overrides) -> Result<Value> {
    let scenario = &spec.scenario;
    let frames = scenario.frames;
    let reference_frames: Vec<u32> = (0..frames).filter(|&f| scenario.reference.wants(f, frames)).collect();
    Ok(json!({
        "scenario": scenario.name,
        "scenario_file": scenario_file.display().to_string(),
        "scenario_text": scenario.source,
        "commit": commit(scenario_file),
        "flicker_version": env!("CARGO_PKG_VERSION"),
        "adapter": gpu.summary,
        "timestamp_queries": gpu.has_timestamps(),
        "seed": scenario.seed,
        "resolution": [scenario.resolution.0, scenario.resolution.1],
        "frames": frames,
        "warmup_frames": scenario.warmup_frames,
        "methods": spec.methods.iter().map(|m| m.label()).collect::<Vec<_>>(),
        "reference": { "spp": scenario.reference.spp, "frames": reference_frames },
        "events": scenario.events_summary().into_iter().filter(|(frame, _)| *frame < frames).map(|(frame, label)| json!({"frame": frame, "label": label})).collect::<Vec<_>>(),
        "regions": scenario.regions.iter().map(|r| json!({"name": r.name, "x": r.x, "y": r.y, "width": r.width, "height": r.height})).collect::<Vec<_>>(),
        "settings": {
            "max_depth": scenario.max_depth,
            "smape_epsilon": scenario.smape_epsilon,
            "time_step": scenario.time_step,
            "methods": spec.methods.iter().map(|m| json!({"label": m.label(), "spp": m.spec.spp(), "spec": m.spec})).collect::<Vec<_>>(),
            "overrides": {
                "frames": overrides.frames,
                "resolution": overrides.resolution.map(|(w, h)| format!("{w}x{h}")),
                "spp": overrides.spp,
                "seed": overrides.seed,
                "out": overrides.out.as_ref().map(|p| p.display().to_string()),
            },
        },
    }))
}

/// The commit of the checkout the tool runs from, with `-dirty` when it has local changes;
/// "unknown" outside a git checkout.
pub fn commit(scenario_file: &Path) -> String {
    let dir = scenario_file.parent().filter(|d| !d.as_os_str().is_empty()).unwrap_or(Path::new("."));
    let git = |args: &[&str]| {
        std::process::Command::new("git")
            .args(args)
            .current_dir(dir)
            .output()
            .ok()
            .filter(|o| o.status.success())
            .map(|o| String::from_utf8_lossy(&o.stdout).trim().to_string())
    };
    match git(&["rev-parse", "HEAD"]) {
        Some(hash) => {
            let dirty = git(&["status", "--porcelain", "--untracked-files=no"]).is_some_and(|s| !s.is_empty());
            if dirty { format!("{hash}-dirty") } else { hash }
        }
        None => "unknown".into(),
    }
}
