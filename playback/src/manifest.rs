//! `manifest.json`: what was run, on what, with which settings — enough to reproduce a run.

use std::path::Path;

use crate::scenario::{Overrides, RunSpec};
use anyhow::Result;
use render::gpu::Gpu;
use serde_json::{Value, json};

/// The scenario's events in recorded frames (frames.csv's `frame`): simulation frame minus the
/// warm-up frames; events during the warm-up or after the last recorded frame are left out.
pub fn recorded_events(scenario: &sim::Scenario) -> Vec<(u32, String)> {
    scenario
        .events_summary()
        .into_iter()
        .filter_map(|(frame, label)| {
            frame
                .checked_sub(scenario.warmup_frames)
                .filter(|f| *f < scenario.frames)
                .map(|f| (f, label))
        })
        .collect()
}

pub fn build(
    spec: &RunSpec,
    scenario_file: &Path,
    gpu: &Gpu,
    overrides: &Overrides,
) -> Result<Value> {
    let scenario = &spec.scenario;
    let frames = scenario.frames;
    let reference_frames: Vec<u32> =
        (0..frames).filter(|&f| scenario.reference.wants(f, frames)).collect();
    Ok(json!({
        "scenario": scenario.name,
        "scenario_file": scenario_file.display().to_string(),
        // Resolves the scenario's relative paths (glTF, grids) when a run is resumed elsewhere.
        "scenario_origin": std::path::absolute(scenario_file).unwrap_or_else(|_| scenario_file.to_path_buf()).display().to_string(),
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
        "events": recorded_events(scenario).into_iter().map(|(frame, label)| json!({"frame": frame, "label": label})).collect::<Vec<_>>(),
        "regions": scenario.regions.iter().map(|r| json!({"name": r.name, "x": r.x, "y": r.y, "width": r.width, "height": r.height})).collect::<Vec<_>>(),
        "settings": {
            "max_depth": scenario.max_depth,
            "smape_epsilon": scenario.smape_epsilon,
            "time_step": scenario.time_step,
            "cvvdp": scenario.cvvdp,
            "methods": spec.methods.iter().map(|m| json!({"label": m.label(), "spp": m.spec.spp(), "temporal_window": m.spec.temporal_window(), "spec": m.spec})).collect::<Vec<_>>(),
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

/// Where a run stands (`status` in manifest.json). A run killed outright stays `running`;
/// manifests from before the field count as complete.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Status {
    Running,
    /// Stopped by SIGINT or SIGTERM after a whole frame.
    Interrupted,
    /// Stopped by an error (`error` holds it).
    Failed,
    Complete,
}

impl Status {
    pub fn name(self) -> &'static str {
        match self {
            Status::Running => "running",
            Status::Interrupted => "interrupted",
            Status::Failed => "failed",
            Status::Complete => "complete",
        }
    }

    /// The status a manifest records.
    pub fn of(manifest: &Value) -> Status {
        match manifest.get("status").and_then(Value::as_str) {
            Some("running") => Status::Running,
            Some("interrupted") => Status::Interrupted,
            Some("failed") => Status::Failed,
            _ => Status::Complete,
        }
    }
}

/// Records where the run stands: its status and the last recorded frame whose images and
/// frames.csv rows are all written (`null` before the first).
pub fn set_status(manifest: &mut Value, status: Status, last_complete_frame: Option<u32>) {
    manifest["status"] = json!(status.name());
    manifest["last_complete_frame"] = json!(last_complete_frame);
}

/// The commit of the checkout the tool runs from, with `-dirty` when it has local changes;
/// "unknown" outside a git checkout.
pub fn commit(scenario_file: &Path) -> String {
    let dir =
        scenario_file.parent().filter(|d| !d.as_os_str().is_empty()).unwrap_or(Path::new("."));
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
            let dirty = git(&["status", "--porcelain", "--untracked-files=no"])
                .is_some_and(|s| !s.is_empty());
            if dirty { format!("{hash}-dirty") } else { hash }
        }
        None => "unknown".into(),
    }
}

#[cfg(test)]
mod tests {
    #[test]
    fn events_are_placed_on_recorded_frames() {
        let tmp = tempfile::tempdir().unwrap();
        let dir = tmp.path().to_path_buf();
        std::fs::create_dir_all(&dir).unwrap();
        let path = dir.join("warm.ron");
        std::fs::write(
            &path,
            "Scenario(scene: Builtin(\"cornell_box\"), resolution: (8, 8), frames: 8, warmup_frames: 8, methods: [PathTracing(spp: 1)],
    events: [(frame: 3, action: Toggle(entity: \"ceiling_light\")), (frame: 12, action: Toggle(entity: \"ceiling_light\"))])",
        )
        .unwrap();
        let mut scenario = sim::Scenario::load(&path).unwrap();
        // A file is refused with an event after its last frame (sim::meaningless); a scenario
        // cut short by --frames can have one.
        scenario.events.push(sim::scenario::EventSpec {
            frame: 16,
            action: sim::scenario::ActionSpec::Toggle { entity: "ceiling_light".into() },
        });
        // Simulation frame 12 is recorded frame 4; 3 falls in the warm-up, 16 after the last frame.
        let frames: Vec<u32> = super::recorded_events(&scenario).into_iter().map(|e| e.0).collect();
        assert_eq!(frames, [4]);
    }
}
