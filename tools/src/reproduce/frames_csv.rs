//! A run's frames.csv read back by `flicker reproduce`: per row the method, the frame and the
//! values of some numeric columns, with errors at the file's line. Pass times (`pass_ms`,
//! `alone`) and the method stats a suite does not keep (`frame_columns`) read it here.

use std::path::Path;

use anyhow::{Context, Result, bail};

/// One frames.csv row: method, frame and the value of each chosen column (`None`: an empty cell).
pub type Row = (String, u32, Vec<Option<f64>>);

/// frames.csv's rows, in file order, with the values of the columns that `pick` chooses from
/// the header (it names what is missing itself).
pub fn rows(path: &Path, pick: impl FnOnce(&[&str]) -> Result<Vec<usize>>) -> Result<Vec<Row>> {
    let text =
        std::fs::read_to_string(path).with_context(|| format!("reading {}", path.display()))?;
    let mut lines = text.lines();
    let header: Vec<&str> = lines.next().unwrap_or_default().split(',').collect();
    let column = |name: &str| header.iter().position(|h| *h == name);
    let (Some(method), Some(frame)) = (column("method"), column("frame")) else {
        bail!("{}: no method and frame columns", path.display())
    };
    let columns = pick(&header)?;
    let mut rows = Vec::new();
    for (i, line) in lines.enumerate() {
        let cells: Vec<&str> = line.split(',').collect();
        let at = || format!("{}:{}", path.display(), i + 2);
        let cell = |c: usize| cells.get(c).copied().with_context(|| format!("{}: short row", at()));
        let values = columns
            .iter()
            .map(|&c| {
                let s = cell(c)?;
                if s.is_empty() {
                    return Ok(None);
                }
                s.parse().map(Some).with_context(|| format!("{}: '{s}' is not a number", at()))
            })
            .collect::<Result<_>>()?;
        let frame = cell(frame)?.parse().with_context(|| format!("{}: frame", at()))?;
        rows.push((cell(method)?.to_string(), frame, values));
    }
    Ok(rows)
}
