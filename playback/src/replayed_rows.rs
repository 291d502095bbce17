//! A resumed run's check that its replay gives the interrupted run's frames: the replayed
//! frames.csv rows against the written ones, cell for cell but the times (`crate::resume`).

use std::path::Path;

use anyhow::{Result, anyhow, bail};
use metrics::frames_csv::Frames;

/// Times differ from run to run; every other column is a result.
fn is_time(column: &str) -> bool {
    column == "cpu_ms" || column.ends_with("_ms") || column.contains("_ms_")
}

/// Checks that `replayed` (frames.csv text of the replayed frames) has `written`'s rows, cell
/// for cell in every column but the times.
pub(crate) fn same_rows(file: &Path, written: &str, replayed: &str) -> Result<()> {
    let written = Frames::parse(written, file)?;
    let replayed = Frames::parse(replayed, Path::new("the replayed frames.csv"))?;
    if written.rows.len() != replayed.rows.len() {
        bail!(
            "{}: has {} rows, the replay of its frames gives {}; expected the same (is the run from another commit?); start it again instead",
            file.display(),
            written.rows.len(),
            replayed.rows.len()
        );
    }
    let text = |v: Option<f64>| v.map(|v| v.to_string()).unwrap_or_default();
    for (w, r) in written.rows.iter().zip(&replayed.rows) {
        let differs = |name: &str, old: String, new: String| {
            anyhow!(
                "{}:{}: {name} of {} at frame {} was '{old}', the replay gives '{new}'; results differ from the interrupted run's (another commit or adapter?); start it again instead",
                file.display(),
                w.line,
                w.method,
                w.frame
            )
        };
        if w.method != r.method {
            return Err(differs("method", w.method.clone(), r.method.clone()));
        }
        if w.frame != r.frame {
            return Err(differs("frame", w.frame.to_string(), r.frame.to_string()));
        }
        for (c, name) in written.columns.iter().enumerate().filter(|(_, n)| !is_time(n)) {
            let old = w.values[c];
            let new = replayed.column(name).and_then(|k| r.values[k]);
            // Bit for bit: the same text gives the same number (NaN included).
            if old.map(f64::to_bits) != new.map(f64::to_bits) {
                return Err(differs(name, text(old), text(new)));
            }
        }
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn rows_must_match_except_times() {
        let file = Path::new("run/frames.csv");
        let a = "method,frame,cpu_ms,gpu_ms_total,smape,nirc_ms\npt,0,1.0,2.0,0.5,3\npt,1,1.0,2.0,0.25,3\n";
        let b = "method,frame,cpu_ms,gpu_ms_total,smape,nirc_ms\npt,0,9.0,8.0,0.5,7\npt,1,9.0,8.0,0.25,1\n";
        same_rows(file, a, b).unwrap();
        let c = b.replace("0.25", "0.26");
        let e = same_rows(file, a, &c).unwrap_err().to_string();
        assert!(e.contains("run/frames.csv:3: smape of pt at frame 1 was '0.25'"), "{e}");
        let e = same_rows(file, a, "method,frame\npt,0\n").unwrap_err().to_string();
        assert!(e.contains("has 2 rows"), "{e}");
    }
}
