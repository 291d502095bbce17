//! `PassMs`: the summed ms of some of a frame's passes, per method, read back from a run's
//! frames.csv (Table 1 of the termination paper times the tracer and the propagation apart).
//! Methods of one run may share a cache whose passes run once a frame: its first method's row
//! books them and the others leave those cells empty (methods/termination/README.md, "One
//! frame"). A method's pass time is its own where its row has it, else its
//! cache's: the nearest row above it in the same frame that has it (frames.csv lists a frame's
//! methods in the scenario's order, a cache's first method first).

use std::path::Path;

use anyhow::{Result, bail};
use frame::run_folder::RunFolder;

use crate::suite::measurement::SeedRun;
use crate::suite::metric::Metric;

use super::frames_csv::{Row, rows};

/// One frames.csv row: method, frame and the ms of each asked pass (`None`: an empty cell).
pub type PassRow = Row;

/// frames.csv's rows, in file order, with the ms of the passes in `passes`; a pass the run has
/// no column for is an error naming it and the file.
pub fn pass_times(path: &Path, passes: &[String]) -> Result<Vec<PassRow>> {
    rows(path, |header| {
        let column = |name: &str| header.iter().position(|h| *h == name);
        // A pass's column is gpu_ms_PASS or wall_ms_PASS, by the clock that timed it.
        let columns: Vec<Option<usize>> = passes
            .iter()
            .map(|p| column(&format!("gpu_ms_{p}")).or_else(|| column(&format!("wall_ms_{p}"))))
            .collect();
        if let Some(i) = columns.iter().position(Option::is_none) {
            let known: Vec<&str> = header
                .iter()
                .filter_map(|h| h.strip_prefix("gpu_ms_").or_else(|| h.strip_prefix("wall_ms_")))
                .filter(|p| *p != "total")
                .collect();
            bail!(
                "{}: no column of pass '{}'; its passes are: {}",
                path.display(),
                passes[i],
                known.join(", ")
            );
        }
        Ok(columns.into_iter().flatten().collect())
    })
}

/// Per row: the sum of its passes, each its own or its cache's (the nearest row above in the
/// same frame that has it); `None` where a pass has neither (a partial sum would look faster).
fn sums(rows: &[PassRow]) -> Vec<Option<f64>> {
    let mut out = Vec::with_capacity(rows.len());
    let mut shared: Vec<Option<f64>> = Vec::new();
    let mut frame = None;
    for (_, f, times) in rows {
        if frame != Some(*f) {
            frame = Some(*f);
            shared = vec![None; times.len()];
        }
        for (s, t) in shared.iter_mut().zip(times) {
            if t.is_some() {
                *s = *t;
            }
        }
        out.push(shared.iter().copied().sum());
    }
    out
}

/// The series key of `PassMs` over `passes` in a seed run's metrics.
pub fn key(passes: &[String]) -> String {
    format!("{} {}", Metric::PassMs.name(), passes.join("+"))
}

/// Adds each method's `PassMs` over `passes` per frame to `run`, under `key(passes)`.
pub fn add(run: &mut SeedRun, passes: &[String]) -> Result<()> {
    let Some(root) = &run.folder else {
        bail!("seed {}: no run folder to read pass times from", run.seed)
    };
    let rows = pass_times(&RunFolder::new(root).frames_csv(), passes)?;
    let key = key(passes);
    for ((method, frame, _), sum) in rows.iter().zip(sums(&rows)) {
        let Some(metrics) = run.methods.get_mut(method) else { continue };
        let series = metrics.entry(key.clone()).or_default();
        if series.len() <= *frame as usize {
            series.resize(*frame as usize + 1, None);
        }
        series[*frame as usize] = sum;
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use std::collections::BTreeMap;

    use super::*;

    /// A method's pass time is its own, else its cache's from the nearest row above in the same
    /// frame (never from another frame); a pass in neither leaves the frame untimed.
    #[test]
    fn a_method_gets_its_own_passes_and_its_caches() {
        let tmp = tempfile::tempdir().unwrap();
        let dir = tmp.path().to_path_buf();
        std::fs::create_dir_all(&dir).unwrap();
        // vb and mse share one cache (vb, first, books tc_propagate); pt has its own.
        std::fs::write(
            dir.join("frames.csv"),
            "method,frame,gpu_ms_total,gpu_ms_tc_propagate,gpu_ms_tc_trace,rays\n\
             vb,0,3.0,2.0,1.0,10\n\
             mse,0,0.5,,0.5,10\n\
             pt,0,4.0,1.5,2.5,10\n\
             vb,1,3.5,2.5,1.0,10\n\
             mse,1,0.25,,0.25,10\n\
             pt,1,4.5,0.5,4.0,10\n",
        )
        .unwrap();
        let methods =
            ["vb", "mse", "pt"].into_iter().map(|m| (m.to_string(), BTreeMap::new())).collect();
        let mut run = SeedRun { seed: 1, methods, jod: BTreeMap::new(), folder: Some(dir.clone()) };
        let both = vec!["tc_trace".to_string(), "tc_propagate".to_string()];
        add(&mut run, &both).unwrap();
        add(&mut run, &both[..1]).unwrap();
        let ms = |run: &SeedRun, m: &str, passes: &[String]| run.methods[m][&key(passes)].clone();
        assert_eq!(ms(&run, "vb", &both), [Some(3.0), Some(3.5)]);
        assert_eq!(ms(&run, "mse", &both), [Some(2.5), Some(2.75)]);
        assert_eq!(ms(&run, "pt", &both), [Some(4.0), Some(4.5)]);
        assert_eq!(ms(&run, "mse", &both[..1]), [Some(0.5), Some(0.25)]);
        // pt first in its frames without a propagation: untimed, not its trace alone, and not
        // given the frame before's.
        std::fs::write(
            dir.join("frames.csv"),
            "method,frame,gpu_ms_tc_propagate,gpu_ms_tc_trace\npt,0,,2.5\nvb,0,2.0,1.0\npt,1,,2.5\n",
        )
        .unwrap();
        add(&mut run, &both).unwrap();
        assert_eq!(ms(&run, "pt", &both), [None, None]);
        let e = add(&mut run, &["tc_propagation".to_string()]).unwrap_err().to_string();
        assert!(
            e.contains(
                "no column of pass 'tc_propagation'; its passes are: tc_propagate, tc_trace"
            ),
            "{e}"
        );
    }
}
