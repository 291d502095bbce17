//! frames.csv, a run's per-frame table: its one schema, writer and reader (through the `csv`
//! crate). It lives here, below `frame` (which writes it) and `report` (which reads it).
//!
//! The schema: a header `method,frame,COLUMN,...`, then one row per (method, frame); every cell
//! after `frame` is a number, and an empty cell means "not measured". Which columns a run has is
//! the writer's caller's business (`frame::frame_record`).

use std::path::Path;

use anyhow::{Context, Result, bail};

/// The file's name in a run folder.
pub const FILE: &str = "frames.csv";

/// One cell as written.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Cell {
    /// Not measured.
    Empty,
    /// A count (rays, pixels).
    Count(u64),
    /// A number with this many decimals.
    Fixed(f64, usize),
}

impl Cell {
    /// A number with 6 decimals, or empty: the cell of most columns.
    pub fn six(v: Option<f64>) -> Self {
        v.map_or(Cell::Empty, |v| Cell::Fixed(v, 6))
    }

    fn text(self) -> String {
        match self {
            Cell::Empty => String::new(),
            Cell::Count(n) => n.to_string(),
            Cell::Fixed(v, decimals) => format!("{v:.decimals$}"),
        }
    }
}

/// Writes the table: the header `method,frame,COLUMNS`, then each row's method, frame and cells
/// (one per column). A method label with a comma or a quote is quoted, as CSV has it.
pub fn write<'a>(
    columns: &[String],
    rows: impl IntoIterator<Item = (&'a str, u32, Vec<Cell>)>,
) -> String {
    let mut out = csv::Writer::from_writer(Vec::new());
    let header = ["method", "frame"].into_iter().chain(columns.iter().map(String::as_str));
    out.write_record(header).expect("writing to memory");
    for (method, frame, cells) in rows {
        assert_eq!(cells.len(), columns.len(), "one cell per column");
        let record = [method.to_string(), frame.to_string()]
            .into_iter()
            .chain(cells.into_iter().map(Cell::text));
        out.write_record(record).expect("writing to memory");
    }
    String::from_utf8(out.into_inner().expect("writing to memory")).expect("UTF-8 cells")
}

/// One row as read.
#[derive(Clone, Debug)]
pub struct Row {
    pub method: String,
    pub frame: u32,
    /// One value per numeric column (`Frames::columns`); `None` for an empty cell.
    pub values: Vec<Option<f64>>,
    /// Line of the file (the header is line 1), for errors.
    pub line: u64,
}

/// frames.csv as read: the columns after `method,frame`, and the rows in file order.
#[derive(Clone, Debug)]
pub struct Frames {
    pub columns: Vec<String>,
    pub rows: Vec<Row>,
}

impl Frames {
    /// The frames.csv of a run folder.
    pub fn load(run_dir: &Path) -> Result<Self> {
        Self::read(&run_dir.join(FILE))
    }

    /// A frames.csv file.
    pub fn read(path: &Path) -> Result<Self> {
        let text = std::fs::read_to_string(path)
            .with_context(|| format!("cannot read {}", path.display()))?;
        Self::parse(&text, path)
    }

    /// `text`, read from `path` (named in errors with the line: `PATH:LINE: ...`).
    pub fn parse(text: &str, path: &Path) -> Result<Self> {
        let file = path.display();
        // csv counts lines without the blank ones it skips, and a record's position is before them.
        let line_at = |p: &csv::Position| {
            let rest = &text[p.byte() as usize..];
            let start = text.len() - rest.trim_start_matches(['\r', '\n']).len();
            text[..start].matches('\n').count() as u64 + 1
        };
        let mut reader = csv::ReaderBuilder::new()
            .has_headers(false)
            .trim(csv::Trim::All)
            .from_reader(text.as_bytes());
        let mut records = reader.records();
        let record_at = |r: csv::Result<csv::StringRecord>| -> Result<csv::StringRecord> {
            r.map_err(|e| {
                let line = e.position().map_or(0, line_at);
                match e.kind() {
                    csv::ErrorKind::UnequalLengths { expected_len, len, .. } => anyhow::anyhow!(
                        "{file}:{line}: the row has {len} cells, the header has {expected_len}"
                    ),
                    _ => anyhow::anyhow!("{file}:{line}: {e}"),
                }
            })
        };
        let Some(header) = records.next() else { bail!("{file}: empty file") };
        let header = record_at(header)?;
        if header.len() < 2 || &header[0] != "method" || &header[1] != "frame" {
            let found: Vec<&str> = header.iter().collect();
            bail!("{file}:1: header must start with `method,frame`, found `{}`", found.join(","));
        }
        let columns: Vec<String> = header.iter().skip(2).map(str::to_string).collect();
        let mut rows = Vec::new();
        for record in records {
            let record = record_at(record)?;
            let line = record.position().map_or(0, line_at);
            let frame = record[1].parse().with_context(|| {
                format!("{file}:{line}: frame `{}` is not a whole number", &record[1])
            })?;
            let values = record
                .iter()
                .skip(2)
                .map(|c| match c {
                    "" => Ok(None),
                    c => c
                        .parse::<f64>()
                        .map(Some)
                        .with_context(|| format!("{file}:{line}: `{c}` is not a number")),
                })
                .collect::<Result<_>>()?;
            rows.push(Row { method: record[0].to_string(), frame, values, line });
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

    /// Whether a column has at least one finite value.
    pub fn has_data(&self, column: usize) -> bool {
        self.rows.iter().any(|r| r.values[column].is_some_and(f64::is_finite))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn parses_empty_cells_and_reports_bad_lines() {
        let csv = "method,frame,cpu_ms,flip\na,0,1.5,\na,1,2.0,0.25\nb,0,3,0.5\n";
        let f = Frames::parse(csv, Path::new("x/frames.csv")).unwrap();
        assert_eq!(f.columns, ["cpu_ms", "flip"]);
        assert_eq!(f.methods(), ["a", "b"]);
        assert_eq!(f.series("a", 1), vec![(1.0, 0.25)]);
        let err = Frames::parse("method,frame,x\na,0,zz\n", Path::new("x/frames.csv")).unwrap_err();
        assert!(format!("{err:#}").contains("x/frames.csv:2:"), "{err:#}");
        let err = Frames::parse("method,frame,x\na,0\n", Path::new("x/frames.csv")).unwrap_err();
        assert!(format!("{err:#}").contains("x/frames.csv:2: the row has 2 cells"), "{err:#}");
        let err = Frames::parse("method,frame\na,x\n", Path::new("x/frames.csv")).unwrap_err();
        assert!(format!("{err:#}").contains("x/frames.csv:2: frame `x`"), "{err:#}");
        let blank = Frames::parse("method,frame,x\n\na, 1 , 2.5 \n", Path::new("f.csv")).unwrap();
        assert_eq!(
            (blank.rows[0].line, blank.rows[0].frame, blank.rows[0].values[0]),
            (3, 1, Some(2.5))
        );
        let err = Frames::parse("method,frame,x\n\na,0\n", Path::new("x/frames.csv")).unwrap_err();
        assert!(format!("{err:#}").contains("x/frames.csv:3: the row has 2 cells"), "{err:#}");
        assert!(Frames::parse("frame,method\n", Path::new("f.csv")).is_err());
        assert!(Frames::parse("", Path::new("f.csv")).is_err());
    }

    #[test]
    fn what_is_written_reads_back() {
        let columns = ["cpu_ms".to_string(), "rays".into(), "flip".into()];
        let rows = [
            ("pt", 0, vec![Cell::Fixed(2.0, 4), Cell::Count(120), Cell::six(Some(0.25))]),
            ("a, \"b\"", 3, vec![Cell::Empty, Cell::Empty, Cell::six(None)]),
        ];
        let text = write(&columns, rows);
        assert_eq!(
            text,
            "method,frame,cpu_ms,rays,flip\npt,0,2.0000,120,0.250000\n\"a, \"\"b\"\"\",3,,,\n"
        );
        let back = Frames::parse(&text, Path::new("frames.csv")).unwrap();
        assert_eq!(back.columns, columns);
        assert_eq!(back.methods(), ["pt", "a, \"b\""]);
        assert_eq!(back.rows[0].values, [Some(2.0), Some(120.0), Some(0.25)]);
        assert_eq!((back.rows[1].frame, back.rows[1].line), (3, 3));
        assert_eq!(back.rows[1].values, [None, None, None]);
    }
}
