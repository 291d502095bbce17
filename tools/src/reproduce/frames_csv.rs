//! A run's frames.csv read back by `flicker reproduce` (through `metrics::frames_csv`): per row
//! the method, the frame and the values of some numeric columns. Pass times (`pass_ms`, `alone`)
//! and the method stats a suite does not keep (`frame_columns`) read it here.

use std::path::Path;

use anyhow::Result;
use metrics::frames_csv::Frames;

/// One frames.csv row: method, frame and the value of each chosen column (`None`: an empty cell).
pub type Row = (String, u32, Vec<Option<f64>>);

/// frames.csv's rows, in file order, with the values of the columns that `pick` chooses from
/// the columns after `method,frame` (it names what is missing itself).
pub fn rows(path: &Path, pick: impl FnOnce(&[&str]) -> Result<Vec<usize>>) -> Result<Vec<Row>> {
    let frames = Frames::read(path)?;
    let columns: Vec<&str> = frames.columns.iter().map(String::as_str).collect();
    let picked = pick(&columns)?;
    Ok(frames
        .rows
        .into_iter()
        .map(|r| (r.method, r.frame, picked.iter().map(|&c| r.values[c]).collect()))
        .collect())
}
