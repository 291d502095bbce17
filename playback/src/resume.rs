//! `flicker run --resume RUN`: continues an interrupted run from its last complete frame.
//!
//! The methods' state at that frame (caches, networks, histories on the GPU) is not saved;
//! the run is played again from frame 0 with the manifest's scenario text and overrides,
//! writing nothing for the frames already on disk, and then goes on writing. Play is
//! deterministic, so the frames are those of an uninterrupted run; the replayed frames.csv
//! rows are checked against the written ones, so a changed commit or adapter that would mix
//! two sets of results is refused.

use std::path::{Path, PathBuf};

use anyhow::{Context, Result, anyhow, bail};
use metrics::frames_csv::Frames;
use render::gpu::Gpu;
use serde_json::Value;

use crate::manifest::Status;
use crate::play::{ResumeAt, RunSummary, play};
use crate::scenario::{Overrides, RunSpec};

/// What must be the same for the replay to give the run's frames.
const SAME: [&str; 8] =
    ["seed", "resolution", "frames", "warmup_frames", "methods", "reference", "adapter", "regions"];

/// What `--resume` reads from a run folder, read and checked before the GPU is touched.
pub struct StoredRun {
    /// manifest.json as written.
    pub manifest: Value,
    pub status: Status,
    /// The scenario file the run was started from.
    pub origin: PathBuf,
    pub overrides: Overrides,
    /// The manifest's scenario text with its overrides.
    pub spec: RunSpec,
    /// frames.csv as written (empty if the run wrote none).
    pub frames_csv: String,
    /// The first recorded frame that frames.csv does not hold.
    pub from: u32,
}

/// Reads RUN/manifest.json and RUN/frames.csv; every error names the file, and the line and
/// column where the text has one.
pub fn read(run: &Path) -> Result<StoredRun> {
    let manifest_file = run.join("manifest.json");
    let manifest = read_manifest(run)?;
    let status = Status::of(&manifest);
    if status == Status::Complete {
        bail!("{}: the run is complete; nothing to resume", manifest_file.display());
    }
    let field = |key: &str| {
        manifest[key]
            .as_str()
            .ok_or_else(|| anyhow!("{}: expected a string field `{key}`", manifest_file.display()))
    };
    let origin = PathBuf::from(field("scenario_origin").or_else(|_| field("scenario_file"))?);
    // The scenario's own errors are at its line and column; the manifest holds its text.
    let in_manifest = |part: &str| format!("{}: {part}", manifest_file.display());
    let scenario = sim::Scenario::from_ron(field("scenario_text")?, &origin)
        .with_context(|| in_manifest("scenario_text"))?;
    let overrides = stored_overrides(&manifest["settings"]["overrides"], run)
        .with_context(|| in_manifest("settings.overrides"))?;
    let spec = RunSpec::from_scenario(scenario, &overrides)
        .with_context(|| in_manifest("scenario_text with settings.overrides"))?;
    let csv_file = run.join("frames.csv");
    let frames_csv = match std::fs::read(&csv_file) {
        Ok(bytes) => String::from_utf8(bytes).map_err(|e| {
            let valid = &e.as_bytes()[..e.utf8_error().valid_up_to()];
            let line = valid.iter().filter(|&&b| b == b'\n').count() + 1;
            anyhow!("{}:{line}: expected UTF-8 text: {}", csv_file.display(), e.utf8_error())
        })?,
        Err(e) if e.kind() == std::io::ErrorKind::NotFound => String::new(),
        Err(e) => return Err(e).with_context(|| format!("reading {}", csv_file.display())),
    };
    let from = last_frame(&frames_csv, &csv_file)?.map_or(0, |f| f + 1);
    if from > spec.scenario.frames {
        bail!(
            "{}:{}: frame {} is beyond the run's {} recorded frames; expected frames below {}",
            csv_file.display(),
            frames_csv.lines().count(),
            from - 1,
            spec.scenario.frames,
            spec.scenario.frames
        );
    }
    Ok(StoredRun { manifest, status, origin, overrides, spec, frames_csv, from })
}

/// RUN/manifest.json, parsed; errors name the file (and the line and column of bad JSON).
fn read_manifest(run: &Path) -> Result<Value> {
    let manifest_file = run.join("manifest.json");
    let bytes = std::fs::read(&manifest_file).with_context(|| {
        format!(
            "{}: cannot read it; expected a run folder of `flicker run`",
            manifest_file.display()
        )
    })?;
    // From bytes: invalid UTF-8 is an error at its line and column too.
    serde_json::from_slice(&bytes).map_err(|e| {
        anyhow!("{}:{}:{}: not valid JSON: {e}", manifest_file.display(), e.line(), e.column())
    })
}

pub fn resume(run: &Path, cache_dir: Option<PathBuf>, progress: bool) -> Result<RunSummary> {
    // Stopped after its last frame, while its report was being written: only the report is left.
    let folder = frame::run_folder::RunFolder::new(run);
    if folder.report_pending().exists() && Status::of(&read_manifest(run)?) == Status::Complete {
        eprintln!("{}: every frame was written; writing its summary and report", run.display());
        remove_temporaries(run)?;
        let report = crate::play::write_report(&folder)?;
        return Ok(RunSummary {
            folder: run.to_path_buf(),
            records: Vec::new(),
            references_rendered: 0,
            references_cached: 0,
            report,
        });
    }
    let StoredRun { manifest: stored, status, origin, overrides, spec, frames_csv, from } =
        read(run)?;
    let manifest_file = run.join("manifest.json");
    let gpu = Gpu::new()?;
    let rebuilt = crate::manifest::build(&spec, &origin, &gpu, &overrides)?;
    let mut differs: Vec<&str> = SAME.into_iter().filter(|k| stored[k] != rebuilt[k]).collect();
    for key in ["max_depth", "smape_epsilon", "time_step", "methods"] {
        if stored["settings"][key] != rebuilt["settings"][key] {
            differs.push(key);
        }
    }
    if !differs.is_empty() {
        bail!(
            "{}: {} of the run differ from what its scenario gives here ({}); expected a run of `flicker run` on this adapter (suites and sweeps rerun their own jobs); start it again instead",
            manifest_file.display(),
            differs.join(", "),
            gpu.summary
        );
    }
    let mut manifest = stored.clone();
    if manifest.get("resumed").is_none() {
        manifest["resumed"] = Value::Array(Vec::new());
    }
    if let Some(list) = manifest["resumed"].as_array_mut() {
        list.push(serde_json::json!({
            "from_frame": from,
            "status": status.name(),
            "commit": rebuilt["commit"],
        }));
    }
    manifest.as_object_mut().map(|m| m.remove("error"));
    remove_temporaries(run)?;
    play(&spec, gpu, manifest, cache_dir, progress, Some(ResumeAt { from, frames_csv }))
}

/// Removes the temporary files (`NAME.tmpPID`, metrics::atomic) of writes that a hard stop
/// (SIGKILL, a power cut) cut short: never a run's output, and each process names its own.
fn remove_temporaries(dir: &Path) -> Result<()> {
    for entry in std::fs::read_dir(dir).with_context(|| format!("reading {}", dir.display()))? {
        let path = entry?.path();
        let name = path.file_name().unwrap_or_default().to_string_lossy().into_owned();
        let temporary = name
            .rsplit_once(".tmp")
            .is_some_and(|(_, pid)| !pid.is_empty() && pid.bytes().all(|b| b.is_ascii_digit()));
        if path.is_dir() {
            remove_temporaries(&path)?;
        } else if temporary {
            std::fs::remove_file(&path)
                .with_context(|| format!("removing the unfinished write {}", path.display()))?;
        }
    }
    Ok(())
}

fn stored_overrides(o: &Value, run: &Path) -> Result<Overrides> {
    let number = |key: &str| -> Result<Option<u64>> {
        match &o[key] {
            Value::Null => Ok(None),
            v => v.as_u64().map(Some).ok_or_else(|| anyhow!("{key}: expected a number, got {v}")),
        }
    };
    let small = |key: &str| -> Result<Option<u32>> {
        number(key)?
            .map(|n| u32::try_from(n).map_err(|_| anyhow!("{key}: {n} is too large")))
            .transpose()
    };
    let resolution = match &o["resolution"] {
        Value::Null => None,
        v => {
            let text = v.as_str().unwrap_or_default();
            let parsed =
                text.split_once('x').and_then(|(w, h)| Some((w.parse().ok()?, h.parse().ok()?)));
            Some(parsed.ok_or_else(|| anyhow!("resolution: expected \"WIDTHxHEIGHT\", got {v}"))?)
        }
    };
    Ok(Overrides {
        frames: small("frames")?,
        resolution,
        spp: small("spp")?,
        seed: number("seed")?,
        out: Some(run.to_path_buf()),
    })
}

/// The frame of frames.csv's last row (the file is rewritten whole after each frame, so every
/// frame it has is complete).
fn last_frame(csv: &str, file: &Path) -> Result<Option<u32>> {
    if csv.trim().is_empty() {
        return Ok(None);
    }
    Ok(Frames::parse(csv, file)?.rows.last().map(|r| r.frame))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn last_frame_is_the_last_rows() {
        let file = Path::new("run/frames.csv");
        let a = "method,frame,cpu_ms,gpu_ms_total,smape,nirc_ms\npt,0,1.0,2.0,0.5,3\npt,1,1.0,2.0,0.25,3\n";
        assert_eq!(last_frame(a, file).unwrap(), Some(1));
        assert_eq!(last_frame("", file).unwrap(), None);
        assert!(last_frame("method,frame\npt,x\n", file).unwrap_err().to_string().contains(":2:"));
    }
}
