//! What the run tests (interrupt.rs, kill_and_full_disk.rs) compare between two runs.

use std::path::Path;

/// frames.csv's rows without the time columns (they differ from run to run).
pub fn results(run: &Path) -> Vec<Vec<String>> {
    let csv = std::fs::read_to_string(run.join("frames.csv")).unwrap();
    let rows: Vec<Vec<&str>> = csv.lines().map(|l| l.split(',').collect()).collect();
    let keep: Vec<usize> = (0..rows[0].len())
        .filter(|&c| {
            let h = rows[0][c];
            !(h == "cpu_ms" || h.ends_with("_ms") || h.contains("_ms_"))
        })
        .collect();
    rows.iter().map(|r| keep.iter().map(|&c| r[c].to_string()).collect()).collect()
}
