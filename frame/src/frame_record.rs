//! One row of `frames.csv`: timings and metrics of one method at one frame.

use metrics::frames_csv::{self, Cell};

#[derive(Clone, Debug, Default)]
pub struct FrameRecord {
    pub method: String,
    pub frame: u32,
    pub cpu_ms: f64,
    /// Time per pass, in the order the passes ran; `None` = not measured.
    pub passes: Vec<(String, Option<f64>)>,
    /// The clock of `passes`: columns `gpu_ms_PASS` (timestamp queries, also when unknown) or
    /// `wall_ms_PASS` (each pass submitted alone and waited for).
    pub clock: Option<render::timing::Clock>,
    /// Rays traced and paths shaded this frame (the method's GPU counters); `None` = not reported.
    pub rays: Option<u64>,
    pub shaded: Option<u64>,
    pub smape: Option<f64>,
    pub smape_reprojected: Option<f64>,
    pub disoccluded: Option<u64>,
    pub flip: Option<f64>,
    pub mse: Option<f64>,
    pub rel_mse: Option<f64>,
    pub psnr: Option<f64>,
    /// Per region of interest: (name, flip, smape).
    pub regions: Vec<(String, Option<f64>, Option<f64>)>,
    /// Method-specific numbers (reliability, occupancy, shaded samples, ...).
    pub stats: Vec<(String, f64)>,
}

impl FrameRecord {
    /// The frame's time: the sum of its passes' times, when it has passes and every one was
    /// timed (frames.csv's total column, a sweep job's frame time, the NIRC frame bench).
    pub fn passes_total_ms(&self) -> Option<f64> {
        let total: Option<f64> = self.passes.iter().map(|(_, t)| *t).sum();
        total.filter(|_| !self.passes.is_empty())
    }
}

fn clock_prefix(row: &FrameRecord) -> &'static str {
    row.clock.unwrap_or(render::timing::Clock::Gpu).name()
}

/// Writes the CSV; pass columns are the union over rows, so methods with different passes share
/// one table. Empty cells mean "not measured".
pub fn to_csv(rows: &[FrameRecord]) -> String {
    let (columns, cells) = table(rows);
    frames_csv::write(
        &columns,
        rows.iter().zip(cells).map(|(r, c)| (r.method.as_str(), r.frame, c)),
    )
}

/// frames.csv's columns after `method,frame`, and each row's cells in them.
pub fn table(rows: &[FrameRecord]) -> (Vec<String>, Vec<Vec<Cell>>) {
    let wall_total = rows.iter().any(|r| clock_prefix(r) == "wall");
    let mut passes: Vec<String> = Vec::new();
    let mut regions: Vec<String> = Vec::new();
    let mut stats: Vec<String> = Vec::new();
    for row in rows {
        for (k, _) in &row.stats {
            if !stats.contains(k) {
                stats.push(k.clone());
            }
        }
        for (p, _) in &row.passes {
            let column = format!("{}_ms_{p}", clock_prefix(row));
            if !passes.contains(&column) {
                passes.push(column);
            }
        }
        for (r, _, _) in &row.regions {
            if !regions.contains(r) {
                regions.push(r.clone());
            }
        }
    }
    let mut columns: Vec<String> = vec!["cpu_ms".into(), "gpu_ms_total".into()];
    if wall_total {
        columns.push("wall_ms_total".into());
    }
    columns.extend(passes.iter().cloned());
    columns.extend(
        [
            "smape",
            "smape_reprojected",
            "disoccluded",
            "flip",
            "mse",
            "rel_mse",
            "psnr",
            "rays",
            "shaded",
        ]
        .map(String::from),
    );
    for r in &regions {
        columns.extend([format!("{r}_flip"), format!("{r}_smape")]);
    }
    columns.extend(stats.iter().cloned());
    let count = |n: Option<u64>| n.map_or(Cell::Empty, Cell::Count);
    let cells = rows
        .iter()
        .map(|row| {
            let total = row.passes_total_ms();
            let wall = clock_prefix(row) == "wall";
            let mut cells =
                vec![Cell::Fixed(row.cpu_ms, 4), Cell::six(if wall { None } else { total })];
            if wall_total {
                cells.push(Cell::six(if wall { total } else { None }));
            }
            cells.extend(passes.iter().map(|p| {
                Cell::six(
                    row.passes
                        .iter()
                        .find(|(q, _)| format!("{}_ms_{q}", clock_prefix(row)) == *p)
                        .and_then(|(_, t)| *t),
                )
            }));
            cells.extend([
                Cell::six(row.smape),
                Cell::six(row.smape_reprojected),
                count(row.disoccluded),
                Cell::six(row.flip),
                Cell::six(row.mse),
                Cell::six(row.rel_mse),
                Cell::six(row.psnr),
                count(row.rays),
                count(row.shaded),
            ]);
            for r in &regions {
                let found = row.regions.iter().find(|(q, _, _)| q == r);
                cells.extend([
                    Cell::six(found.and_then(|f| f.1)),
                    Cell::six(found.and_then(|f| f.2)),
                ]);
            }
            cells.extend(
                stats
                    .iter()
                    .map(|k| Cell::six(row.stats.iter().find(|(q, _)| q == k).map(|s| s.1))),
            );
            cells
        })
        .collect();
    (columns, cells)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn union_of_passes_and_empty_cells() {
        let a = FrameRecord {
            method: "pt_1spp".into(),
            frame: 0,
            cpu_ms: 2.0,
            passes: vec![("trace".into(), Some(1.5))],
            smape: Some(0.25),
            rays: Some(120),
            shaded: Some(40),
            stats: vec![("occupancy".into(), 0.5)],
            ..Default::default()
        };
        let b = FrameRecord {
            method: "pt_4spp".into(),
            frame: 0,
            passes: vec![("shade".into(), None)],
            ..Default::default()
        };
        let csv = to_csv(&[a, b]);
        let lines: Vec<&str> = csv.lines().collect();
        assert_eq!(
            lines[0],
            "method,frame,cpu_ms,gpu_ms_total,gpu_ms_trace,gpu_ms_shade,smape,smape_reprojected,disoccluded,flip,mse,rel_mse,psnr,rays,shaded,occupancy"
        );
        assert_eq!(lines[1], "pt_1spp,0,2.0000,1.500000,1.500000,,0.250000,,,,,,,120,40,0.500000");
        assert_eq!(lines[2], "pt_4spp,0,0.0000,,,,,,,,,,,,,");
    }

    #[test]
    fn wall_clock_passes_get_their_own_columns() {
        let a = FrameRecord {
            method: "taa".into(),
            passes: vec![("taa_trace".into(), Some(3.0)), ("taa_resolve".into(), Some(1.0))],
            clock: Some(render::timing::Clock::Wall),
            ..Default::default()
        };
        let b = FrameRecord {
            method: "pt_1spp".into(),
            passes: vec![("path_trace".into(), Some(2.0))],
            clock: Some(render::timing::Clock::Gpu),
            ..Default::default()
        };
        let csv = to_csv(&[a, b]);
        let lines: Vec<&str> = csv.lines().collect();
        assert!(lines[0].starts_with("method,frame,cpu_ms,gpu_ms_total,wall_ms_total,wall_ms_taa_trace,wall_ms_taa_resolve,gpu_ms_path_trace,smape"), "{}", lines[0]);
        assert!(lines[1].starts_with("taa,0,0.0000,,4.000000,3.000000,1.000000,,"), "{}", lines[1]);
        assert!(lines[2].starts_with("pt_1spp,0,0.0000,2.000000,,,,2.000000,"), "{}", lines[2]);
    }
}
