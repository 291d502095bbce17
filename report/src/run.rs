//! Reading a run folder: the manifest and frames.csv.

use std::path::{Path, PathBuf};

use anyhow::{Context, bail};
use metrics::Region;
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
    /// Effective temporal window, frames (systems::methods::temporal_window); absent in runs
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

/// The run's memory (the manifest's `memory`, written by systems::memory after the frames);
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

/// One row of frames.csv.
#[derive(Clone, Debug)]
pub struct Row {
    pub method: String,
    pub frame: u32,
    /// One value per numeric column (`Frames::columns`); `None` for an empty cell.
    pub values: Vec<Option<f64>>,
}

/// frames.csv: columns after `method,frame`, and the rows.
#[derive(Clone, Debug)]
pub struct Frames {
    pub columns: Vec<String>,
    pub rows: Vec<Row>,
}

impl Frames {
    pub fn load(run_dir: &Path) -> anyhow::Result<Self> {
        let path = run_dir.join("frames.csv");
        let text = std::fs::read_to_string(&path)
            .with_context(|| format!("cannot read {}", path.display()))?;
        Self::parse(&text, &path)
    }

    pub fn parse(text: &str, path: &Path) -> anyhow::Result<Self> {
        let mut lines = text.lines().filter(|l| !l.trim().is_empty());
        let header: Vec<&str> = lines
            .next()
            .with_context(|| format!("{}: empty file", path.display()))?
            .split(',')
            .collect();
        if header.len() < 2 || header[0] != "method" || header[1] != "frame" {
            bail!(
                "{}: header must start with `method,frame`, found `{}`",
                path.display(),
                header.join(",")
            );
        }
        let columns: Vec<String> = header[2..].iter().map(|s| s.trim().to_string()).collect();
        let mut rows = Vec::new();
        for (i, line) in lines.enumerate() {
            let cells: Vec<&str> = line.split(',').collect();
            if cells.len() != header.len() {
                bail!(
                    "{}: line {} has {} cells, the header has {}",
                    path.display(),
                    i + 2,
                    cells.len(),
                    header.len()
                );
            }
            let frame = cells[1].trim().parse().with_context(|| {
                format!(
                    "{}: line {}: frame `{}` is not an integer",
                    path.display(),
                    i + 2,
                    cells[1]
                )
            })?;
            let values = cells[2..]
                .iter()
                .map(|c| {
                    let c = c.trim();
                    if c.is_empty() {
                        Ok(None)
                    } else {
                        c.parse::<f64>().map(Some).with_context(|| {
                            format!("{}: line {}: `{c}` is not a number", path.display(), i + 2)
                        })
                    }
                })
                .collect::<anyhow::Result<_>>()?;
            rows.push(Row { method: cells[0].trim().to_string(), frame, values });
        }
        Ok(Self { columns, rows })
    }

    pub fn column(&self, name: &str) -> Option<usize> {
        self.columns.iter().position(|c| c == name)
    }

    /// Methods in order of first appearance.
    pub fn methods(&self) -> Vec<String> {
        let mut out: Vec<String> = Vec::new();
        for r in &self.rows {
            if !out.contains(&r.method) {
                out.push(r.method.clone());
            }
        }
        out
    }

    /// (frame, value) of a column for one method, skipping empty cells, sorted by frame.
    pub fn series(&self, method: &str, column: usize) -> Vec<(f64, f64)> {
        let mut s: Vec<(f64, f64)> = self
            .rows
            .iter()
            .filter(|r| r.method == method)
            .filter_map(|r| r.values[column].map(|v| (r.frame as f64, v)))
            .collect();
        s.sort_by(|a, b| a.0.total_cmp(&b.0));
        s
    }

    /// Frames of the run: those in frames.csv, or the manifest's count if larger.
    pub fn frame_count(&self, manifest: &Manifest) -> u32 {
        self.rows.iter().map(|r| r.frame + 1).max().unwrap_or(0).max(manifest.frames.unwrap_or(0))
    }

    /// Whether a column has at least one finite value.
    pub fn has_data(&self, column: usize) -> bool {
        self.rows.iter().any(|r| r.values[column].is_some_and(f64::is_finite))
    }
}

/// The folder of a method's motion vectors, `frames/METHOD/motion/` (as systems::run_folder).
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

    #[test]
    fn parses_empty_cells_and_reports_bad_lines() {
        let csv = "method,frame,cpu_ms,flip\na,0,1.5,\na,1,2.0,0.25\nb,0,3,0.5\n";
        let f = Frames::parse(csv, Path::new("x/frames.csv")).unwrap();
        assert_eq!(f.columns, ["cpu_ms", "flip"]);
        assert_eq!(f.methods(), ["a", "b"]);
        assert_eq!(f.series("a", 1), vec![(1.0, 0.25)]);
        let err = Frames::parse("method,frame,x\na,0,zz\n", Path::new("x/frames.csv")).unwrap_err();
        assert!(format!("{err:#}").contains("line 2") && format!("{err:#}").contains("frames.csv"));
        assert!(Frames::parse("frame,method\n", Path::new("f.csv")).is_err());
    }
}
