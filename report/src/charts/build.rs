//! The charts of a run: every metric against frame (events marked), and speed against accuracy
//! (mean frame time against mean FLIP and mean SMAPE, Pareto front drawn).

use std::path::Path;

use anyhow::Context;
use metrics::frames_csv::Frames;

use super::plot::{self, XMap};
use super::{Chart, Kind, Series, pareto_front};
use crate::declared::MethodChart;
use crate::run::Manifest;

/// Human-readable names of the columns every method has (a method names its own in its
/// declared charts).
fn label(column: &str) -> String {
    match column {
        "flip" => "FLIP vs reference".into(),
        "smape" => "SMAPE vs previous frame".into(),
        "smape_reprojected" => "SMAPE vs reprojected previous frame".into(),
        "disoccluded" => "disoccluded pixels".into(),
        "psnr" => "PSNR (dB)".into(),
        "mse" => "MSE".into(),
        "rel_mse" => "relative MSE".into(),
        "cpu_ms" => "CPU time (ms)".into(),
        "gpu_ms_total" => "GPU time (ms)".into(),
        "wall_ms_total" => "wall time of the passes (ms)".into(),
        c => c.replace('_', " "),
    }
}

/// Columns of every method charted against frame, in this order; then the methods' declared
/// columns (`MethodChart::Column`), then per-region FLIP and SMAPE.
const FRAME_COLUMNS: [&str; 8] = [
    "flip",
    "smape",
    "smape_reprojected",
    "psnr",
    "rel_mse",
    "gpu_ms_total",
    "wall_ms_total",
    "cpu_ms",
];

fn mean(v: &[(f64, f64)]) -> Option<f64> {
    let f: Vec<f64> = v.iter().map(|p| p.1).filter(|x| x.is_finite()).collect();
    (!f.is_empty()).then(|| f.iter().sum::<f64>() / f.len() as f64)
}

/// Every column against frame, one line per method: the common ones, the `declared` columns of
/// the methods, the regions'.
pub fn frame_charts(
    manifest: &Manifest,
    frames: &Frames,
    declared: &[MethodChart],
) -> Vec<(String, Chart)> {
    let methods = frames.methods();
    let last_frame = frames
        .rows
        .iter()
        .map(|r| r.frame)
        .max()
        .unwrap_or(0)
        .max(manifest.frames.unwrap_or(1).saturating_sub(1)) as f64;
    let events: Vec<(f64, String)> =
        manifest.events.iter().map(|e| (e.frame as f64, e.label.clone())).collect();
    let common = FRAME_COLUMNS.iter().map(|s| (s.to_string(), label(s)));
    let of_methods = declared.iter().filter_map(|c| match c {
        MethodChart::Column { column, label } => Some((column.to_string(), label.to_string())),
        MethodChart::Columns { .. } => None,
    });
    let regions = manifest.regions.iter().flat_map(|r| {
        [format!("{}_flip", r.name), format!("{}_smape", r.name)].map(|c| {
            let l = label(&c);
            (c, l)
        })
    });
    let columns: Vec<(String, String)> = common.chain(of_methods).chain(regions).collect();
    columns
        .into_iter()
        .filter_map(|(name, label)| {
            let c = frames.column(&name).filter(|&c| frames.has_data(c))?;
            let series = methods
                .iter()
                .map(|m| Series { name: m.clone(), points: frames.series(m, c) })
                .collect();
            let chart = Chart {
                title: format!("{label} — {}", manifest.scenario),
                x_label: "frame".into(),
                y_label: label,
                kind: Kind::Lines,
                series,
                events: events.clone(),
                pareto: vec![],
                x_extent: vec![0.0, last_frame],
            };
            Some((format!("frames_{name}"), chart))
        })
        .collect()
}

/// A method's `MethodChart::Columns` chart: its columns against frame for the first method
/// with data in the first required column, with the reference lines; `None` where a required
/// column has no data (a run without the method) or for a `Column` chart.
pub fn method_chart(
    manifest: &Manifest,
    frames: &Frames,
    chart: &MethodChart,
) -> Option<(String, Chart)> {
    let MethodChart::Columns { stem, title, y_label, series, lines } = *chart else {
        return None;
    };
    let with_data = |column: &str| frames.column(column).filter(|&c| frames.has_data(c));
    if series.iter().any(|s| s.required && with_data(s.column).is_none()) {
        return None;
    }
    let key = with_data(series.iter().find(|s| s.required)?.column)?;
    let method = frames
        .methods()
        .into_iter()
        .find(|m| frames.series(m, key).iter().any(|p| p.1.is_finite()))?;
    let last_frame = frames.rows.iter().map(|r| r.frame).max().unwrap_or(0) as f64;
    let mut drawn: Vec<Series> = series
        .iter()
        .filter_map(|s| {
            let c = with_data(s.column)?;
            Some(Series { name: s.legend.into(), points: frames.series(&method, c) })
        })
        .collect();
    drawn.extend(lines.iter().map(|&(y, legend)| Series {
        name: legend.into(),
        points: vec![(0.0, y), (last_frame, y)],
    }));
    let chart = Chart {
        title: format!("{title} ({method}) — {}", manifest.scenario),
        x_label: "frame".into(),
        y_label: y_label.into(),
        kind: Kind::Lines,
        series: drawn,
        events: manifest.events.iter().map(|e| (e.frame as f64, e.label.clone())).collect(),
        pareto: vec![],
        x_extent: vec![0.0, last_frame],
    };
    Some((stem.to_string(), chart))
}

pub fn speed_accuracy_charts(manifest: &Manifest, frames: &Frames) -> Vec<(String, Chart)> {
    let time_col = ["gpu_ms_total", "wall_ms_total", "cpu_ms"]
        .into_iter()
        .find(|c| frames.column(c).is_some_and(|i| frames.has_data(i)));
    let Some(time_col) = time_col else { return vec![] };
    let t = frames.column(time_col).unwrap();
    let mut out =
        scatter_charts(manifest, frames, "", &format!("mean {}", label(time_col)), |method| {
            mean(&frames.series(method, t))
        });
    // variance-trading-termination.txt's Table 1 separates the tracer from the cache's
    // propagation: their sum is the cost a termination rule trades against accuracy (the
    // record fold and the vertex store are per record, the same for every rule).
    let trace = frames.column("gpu_ms_tc_trace").filter(|&c| frames.has_data(c));
    let propagate = frames.column("gpu_ms_tc_propagate").filter(|&c| frames.has_data(c));
    if let (Some(trace), Some(propagate)) = (trace, propagate) {
        // Rules that share a cache report its propagation in the row of its first method (the
        // rules listed before path tracing, which has its own): a rule without one reads the
        // nearest method above it that has one.
        let methods = frames.methods();
        let propagation = |method: &str| {
            let at = methods.iter().position(|m| m == method)?;
            methods[..=at].iter().rev().find_map(|m| mean(&frames.series(m, propagate)))
        };
        out.extend(scatter_charts(
            manifest,
            frames,
            "_tracer_propagation",
            "mean tracer + propagation GPU time (ms)",
            |method| Some(mean(&frames.series(method, trace))? + propagation(method)?),
        ));
    }
    out
}

/// One scatter chart per accuracy metric: every method with a cost (`cost`, the x axis) and
/// the metric's mean, and the Pareto front of those points.
fn scatter_charts(
    manifest: &Manifest,
    frames: &Frames,
    suffix: &str,
    x_label: &str,
    cost: impl Fn(&str) -> Option<f64>,
) -> Vec<(String, Chart)> {
    let mut out = Vec::new();
    for metric in ["flip", "smape"] {
        let Some(m) = frames.column(metric).filter(|&m| frames.has_data(m)) else { continue };
        let series: Vec<Series> = frames
            .methods()
            .into_iter()
            .filter_map(|method| {
                let (x, y) = (cost(&method)?, mean(&frames.series(&method, m))?);
                Some(Series { name: method, points: vec![(x, y)] })
            })
            .collect();
        if series.is_empty() {
            continue;
        }
        let pts: Vec<(f64, f64)> = series.iter().map(|s| s.points[0]).collect();
        let what = if suffix.is_empty() { String::new() } else { format!(", {x_label}") };
        out.push((
            format!("speed_vs_{metric}{suffix}"),
            Chart {
                title: format!(
                    "Speed vs accuracy ({}{what}) — {}",
                    metric.to_uppercase(),
                    manifest.scenario
                ),
                x_label: x_label.into(),
                y_label: format!("mean {}", label(metric)),
                kind: Kind::Scatter,
                pareto: pareto_front(&pts),
                series,
                events: vec![],
                x_extent: vec![],
            },
        ));
    }
    out
}

/// JOD per method and window as the summary has it (window name -> JOD), with each window's
/// frames: read from RUN/summary.json, written before the charts (crate::jod).
pub struct JodTable {
    pub windows: Vec<(String, u32, u32)>,
    pub methods: Vec<(String, std::collections::BTreeMap<String, f64>)>,
}

impl JodTable {
    pub fn load(run_dir: &Path) -> Option<Self> {
        let text = std::fs::read_to_string(run_dir.join("summary.json")).ok()?;
        let v: serde_json::Value = serde_json::from_str(&text).ok()?;
        let windows = v["windows"]
            .as_array()?
            .iter()
            .filter_map(|w| {
                Some((
                    w["name"].as_str()?.to_string(),
                    w["first"].as_u64()? as u32,
                    w["last"].as_u64()? as u32,
                ))
            })
            .collect();
        let methods: Vec<_> = v["methods"]
            .as_array()?
            .iter()
            .filter_map(|m| {
                let jod = serde_json::from_value(m.get("jod")?.clone()).ok()?;
                Some((m["method"].as_str()?.to_string(), jod))
            })
            .collect();
        (!methods.is_empty()).then_some(Self { windows, methods })
    }
}

/// JOD of each window drawn across the window's frames (one step per window), so a method's
/// visible error before and after each event reads off one chart.
pub fn jod_chart(manifest: &Manifest, frames: &Frames, jod: &JodTable) -> Option<(String, Chart)> {
    let series: Vec<Series> = jod
        .methods
        .iter()
        .map(|(method, by_window)| {
            let points = jod
                .windows
                .iter()
                .filter(|(name, ..)| name != "overall")
                .filter_map(|(name, first, last)| {
                    let v = *by_window.get(name)?;
                    Some([(*first as f64, v), (*last as f64 + 1.0, v)])
                })
                .flatten()
                .collect();
            Series { name: method.clone(), points }
        })
        .filter(|s: &Series| !s.points.is_empty())
        .collect();
    if series.is_empty() {
        return None;
    }
    let last = manifest.frame_count(frames) as f64;
    let chart = Chart {
        title: format!("JOD per window (ColorVideoVDP, 10 = invisible) — {}", manifest.scenario),
        x_label: "frame".into(),
        y_label: "JOD".into(),
        kind: Kind::Lines,
        series,
        events: manifest.events.iter().map(|e| (e.frame as f64, e.label.clone())).collect(),
        pareto: vec![],
        x_extent: vec![0.0, last],
    };
    Some(("windows_jod".into(), chart))
}

/// Speed against JOD over the whole run; the front is of cost and 10 - JOD (both minimised).
pub fn speed_jod_chart(
    manifest: &Manifest,
    frames: &Frames,
    jod: &JodTable,
) -> Option<(String, Chart)> {
    let time_col = ["gpu_ms_total", "wall_ms_total", "cpu_ms"]
        .into_iter()
        .find(|c| frames.column(c).is_some_and(|i| frames.has_data(i)))?;
    let t = frames.column(time_col)?;
    let series: Vec<Series> = jod
        .methods
        .iter()
        .filter_map(|(method, by_window)| {
            let x = mean(&frames.series(method, t))?;
            Some(Series { name: method.clone(), points: vec![(x, *by_window.get("overall")?)] })
        })
        .collect();
    if series.is_empty() {
        return None;
    }
    let lost: Vec<(f64, f64)> =
        series.iter().map(|s| (s.points[0].0, 10.0 - s.points[0].1)).collect();
    let chart = Chart {
        title: format!("Speed vs accuracy (JOD) — {}", manifest.scenario),
        x_label: format!("mean {}", label(time_col)),
        y_label: "JOD (higher is better)".into(),
        kind: Kind::Scatter,
        pareto: pareto_front(&lost).into_iter().map(|(x, l)| (x, 10.0 - l)).collect(),
        series,
        events: vec![],
        x_extent: vec![],
    };
    Some(("speed_vs_jod".into(), chart))
}

/// A chart written to RUN/charts/<stem>.svg and .png.
pub struct WrittenChart {
    pub stem: String,
    pub title: String,
    pub svg: String,
    /// Where frames lie along x, for charts drawn against frame.
    pub frame_axis: Option<XMap>,
}

/// Writes every chart the run has data for, the methods' `declared` ones among them.
pub fn write_charts(
    run_dir: &Path,
    manifest: &Manifest,
    frames: &Frames,
    declared: &[MethodChart],
) -> anyhow::Result<Vec<WrittenChart>> {
    let dir = run_dir.join("charts");
    std::fs::create_dir_all(&dir).with_context(|| format!("cannot create {}", dir.display()))?;
    let mut out = Vec::new();
    let jod = JodTable::load(run_dir);
    let jod_charts = jod.iter().flat_map(|j| {
        jod_chart(manifest, frames, j).into_iter().chain(speed_jod_chart(manifest, frames, j))
    });
    let of_methods = declared.iter().filter_map(|c| method_chart(manifest, frames, c));
    for (stem, chart) in frame_charts(manifest, frames, declared)
        .into_iter()
        .chain(of_methods)
        .chain(speed_accuracy_charts(manifest, frames))
        .chain(jod_charts)
    {
        let (svg, map) = plot::to_svg(&chart)?;
        let svg_path = dir.join(format!("{stem}.svg"));
        metrics::atomic::write_bytes(&svg_path, &svg)?;
        let png_path = dir.join(format!("{stem}.png"));
        metrics::atomic::write_bytes(&png_path, plot::to_png(&chart)?)?;
        let frame_axis = (chart.kind == Kind::Lines && chart.x_label == "frame").then_some(map);
        out.push(WrittenChart { stem, title: chart.title, svg, frame_axis });
    }
    Ok(out)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn declared_columns_are_charted_after_the_common_ones_and_before_the_regions() {
        let csv = "method,frame,cpu_ms,flip,steps,empty,roi_flip\n\
                   a,0,1,0.5,2,,0.1\na,1,1,0.4,3,,0.2\nb,0,1,0.6,,,0.3\n";
        let frames = Frames::parse(csv, Path::new("frames.csv")).unwrap();
        let manifest: Manifest = serde_json::from_str(
            r#"{"scenario": "s", "frames": 2, "regions": [{"name": "roi", "x": 0, "y": 0, "width": 1, "height": 1}]}"#,
        )
        .unwrap();
        let declared = [
            MethodChart::Column { column: "steps", label: "steps taken" },
            MethodChart::Column { column: "empty", label: "no data" },
        ];
        let charts = frame_charts(&manifest, &frames, &declared);
        let stems: Vec<&str> = charts.iter().map(|c| c.0.as_str()).collect();
        assert_eq!(stems, ["frames_flip", "frames_cpu_ms", "frames_steps", "frames_roi_flip"]);
        let steps = &charts[2].1;
        assert_eq!(
            (steps.title.as_str(), steps.y_label.as_str()),
            ("steps taken — s", "steps taken")
        );
        assert_eq!(steps.series[0].points, vec![(0.0, 2.0), (1.0, 3.0)]);
        // Without the declaration the column is not drawn.
        assert_eq!(frame_charts(&manifest, &frames, &[]).len(), 3);
        assert!(method_chart(&manifest, &frames, &declared[0]).is_none(), "a Column chart");
    }

    #[test]
    fn termination_runs_chart_tracer_plus_propagation_time_with_its_pareto_front() {
        // Three rules and a path tracer without the cache's passes: the termination chart's x is
        // the mean of tc_trace plus the mean of tc_propagate; the path tracer is left out of it.
        // mse shares vb's cache (no propagation of its own): it reads vb's.
        let csv = "method,frame,gpu_ms_total,gpu_ms_tc_trace,gpu_ms_tc_propagate,gpu_ms_pt,flip,smape\n\
                   vb,0,9,2,5,,0.5,\nvb,1,9,4,5,,,0.2\n\
                   mse,0,9,1,,,0.6,\nmse,1,9,1,,,,0.1\n\
                   spread,0,1,4,4,,0.7,\nspread,1,1,4,4,,,0.3\n\
                   pt,0,3,,,3,0.4,\npt,1,3,,,3,,0.4\n";
        let frames = Frames::parse(csv, Path::new("frames.csv")).unwrap();
        let manifest: Manifest = serde_json::from_str(r#"{"scenario": "s", "frames": 2}"#).unwrap();
        let charts = speed_accuracy_charts(&manifest, &frames);
        let stems: Vec<&str> = charts.iter().map(|c| c.0.as_str()).collect();
        assert_eq!(
            stems,
            [
                "speed_vs_flip",
                "speed_vs_smape",
                "speed_vs_flip_tracer_propagation",
                "speed_vs_smape_tracer_propagation"
            ]
        );
        let flip = &charts[2].1;
        let pts: Vec<(&str, (f64, f64))> =
            flip.series.iter().map(|s| (s.name.as_str(), s.points[0])).collect();
        assert_eq!(pts, [("vb", (8.0, 0.5)), ("mse", (6.0, 0.6)), ("spread", (8.0, 0.7))]);
        // spread costs as much as vb with a larger error: dominated.
        assert_eq!(flip.pareto, vec![(6.0, 0.6), (8.0, 0.5)]);
        assert_eq!(charts[3].1.pareto, vec![(6.0, 0.1)]);
        // The total-time chart keeps every method (spread is fastest there).
        assert_eq!(charts[0].1.pareto, vec![(1.0, 0.7), (3.0, 0.4)]);
    }
}
