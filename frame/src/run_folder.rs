//! The layout of a run folder, in one place (docs/getting-started.md documents it for users).
//!
//! ```text
//! RUN/manifest.json              scenario, commit, adapter, seed, settings, events, regions
//! RUN/frames.csv                 one row per (method, frame): timings and metrics
//! RUN/frames/METHOD/NNNN.exr     linear HDR radiance, and NNNN.png tone-mapped
//! RUN/frames/METHOD/motion/NNNN.exr  motion vectors (R, G: pixels to the previous frame)
//! RUN/reference/NNNN.exr         path-traced reference of frame NNNN, and NNNN.png
//! RUN/summary.json, RUN/report.html, RUN/charts/
//! RUN/report.pending             while a complete run's summary and report are being written
//! ```

use std::path::{Path, PathBuf};

use anyhow::{Context, Result, bail};

/// The name of a method's motion-vector images (`frames/METHOD/motion/NNNN.exr`).
pub const MOTION: &str = "motion";

#[derive(Clone, Debug)]
pub struct RunFolder {
    pub root: PathBuf,
}

impl RunFolder {
    pub fn new(root: impl Into<PathBuf>) -> Self {
        Self { root: root.into() }
    }

    pub fn manifest(&self) -> PathBuf {
        self.root.join("manifest.json")
    }

    pub fn frames_csv(&self) -> PathBuf {
        self.root.join("frames.csv")
    }

    pub fn frame(&self, method: &str, frame: u32, ext: &str) -> PathBuf {
        self.root.join("frames").join(method).join(format!("{frame:04}.{ext}"))
    }

    /// A method's extra image, e.g. `frames/nirc_blend/preference/0003.png`.
    pub fn method_image(&self, method: &str, name: &str, frame: u32, ext: &str) -> PathBuf {
        self.root.join("frames").join(method).join(name).join(format!("{frame:04}.{ext}"))
    }

    /// Stands beside a manifest that says "complete" until the summary, the JOD maps and the
    /// report are written: a run stopped in between is complete but its report is not, and
    /// `--resume` writes it.
    pub fn report_pending(&self) -> PathBuf {
        self.root.join("report.pending")
    }

    pub fn reference(&self, frame: u32, ext: &str) -> PathBuf {
        self.root.join("reference").join(format!("{frame:04}.{ext}"))
    }

    /// Makes the folder ready for a new run. A folder holding an earlier run (it has a
    /// manifest) is replaced; a non-empty folder that is not a run is refused, so a typo in
    /// `--out` can never delete someone's files.
    pub fn prepare(&self) -> Result<()> {
        if self.root.exists() {
            let is_empty = std::fs::read_dir(&self.root)
                .with_context(|| format!("reading {}", self.root.display()))?
                .next()
                .is_none();
            if !is_empty {
                if !self.manifest().exists() {
                    bail!(
                        "output folder {} is not empty and holds no earlier run (no manifest.json); choose another --out",
                        self.root.display()
                    );
                }
                for entry in ["frames", "reference", "charts"] {
                    remove_if_exists(&self.root.join(entry))?;
                }
                for file in
                    ["manifest.json", "frames.csv", "summary.json", "report.html", "report.pending"]
                {
                    remove_if_exists(&self.root.join(file))?;
                }
            }
        }
        std::fs::create_dir_all(&self.root)
            .with_context(|| format!("creating {}", self.root.display()))
    }
}

fn remove_if_exists(path: &Path) -> Result<()> {
    let result =
        if path.is_dir() { std::fs::remove_dir_all(path) } else { std::fs::remove_file(path) };
    match result {
        Err(e) if e.kind() != std::io::ErrorKind::NotFound => {
            Err(e).with_context(|| format!("removing {}", path.display()))
        }
        _ => Ok(()),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn refuses_foreign_folders_and_replaces_runs() {
        let tmp = tempfile::tempdir().unwrap();
        let dir = tmp.path().to_path_buf();
        std::fs::create_dir_all(&dir).unwrap();
        std::fs::write(dir.join("thesis.tex"), "precious").unwrap();
        let run = RunFolder::new(&dir);
        let err = run.prepare().unwrap_err().to_string();
        assert!(err.contains("not empty"), "{err}");
        assert!(dir.join("thesis.tex").exists());

        std::fs::remove_file(dir.join("thesis.tex")).unwrap();
        std::fs::write(run.manifest(), "{}").unwrap();
        std::fs::create_dir_all(run.frame("pt_1spp", 0, "exr").parent().unwrap()).unwrap();
        std::fs::write(run.frame("pt_1spp", 0, "exr"), "old").unwrap();
        run.prepare().unwrap();
        assert!(!run.frame("pt_1spp", 0, "exr").exists());
        assert!(!run.manifest().exists());
    }
}
