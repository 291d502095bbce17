//! The summary table: means per method and frame window, the best method of each column marked.

use maud::{Markup, html};
use metrics::frames_csv::Frames;

use crate::run::Memory;
use crate::summary::Summary;

/// Columns of the table, when present: (frames.csv column, heading, which way is better).
/// `jod` is not a frames.csv column but the summary's JOD of the window (crate::jod).
const COLUMNS: [(&str, &str, Better); 11] = [
    ("jod", "JOD", Better::Higher),
    ("flip", "FLIP", Better::Lower),
    ("smape", "SMAPE", Better::Lower),
    ("smape_reprojected", "SMAPE (reproj.)", Better::Lower),
    ("psnr", "PSNR dB", Better::Higher),
    ("rel_mse", "rel. MSE", Better::Lower),
    ("gpu_ms_total", "GPU ms", Better::Lower),
    ("wall_ms_total", "pass wall ms", Better::Lower),
    ("cpu_ms", "CPU ms", Better::Lower),
    ("rays", "rays", Better::Neither),
    ("shaded", "shaded paths", Better::Neither),
];

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Better {
    Lower,
    Higher,
    /// A count, not a quality: nothing is marked.
    Neither,
}

/// Index of the best value, when at least two methods have one and one of them is best.
pub fn best(values: &[Option<f64>], better: Better) -> Option<usize> {
    let finite: Vec<(usize, f64)> = values
        .iter()
        .enumerate()
        .filter_map(|(i, v)| v.filter(|v| v.is_finite()).map(|v| (i, v)))
        .collect();
    if finite.len() < 2 || better == Better::Neither {
        return None;
    }
    let pick = |a: &(usize, f64), b: &(usize, f64)| {
        if better == Better::Lower { a.1.total_cmp(&b.1) } else { b.1.total_cmp(&a.1) }
    };
    let best = finite.iter().min_by(|a, b| pick(a, b))?;
    // A tie marks nobody: "best" must mean something.
    (finite.iter().filter(|v| v.1 == best.1).count() == 1).then_some(best.0)
}

/// Whether the table has column `c`: a frames.csv column with data, or JOD where computed.
fn shown(summary: &Summary, frames: &Frames, c: &str) -> bool {
    if c == "jod" {
        return summary.methods.iter().any(|m| !m.jod.is_empty());
    }
    frames.column(c).is_some_and(|i| frames.has_data(i))
}

/// Method `m`'s value of column `c` over window `w`: its mean, or its JOD.
fn cell(summary: &Summary, m: usize, w: &str, c: &str) -> Option<f64> {
    let m = &summary.methods[m];
    if c == "jod" {
        return m.jod.get(w).copied();
    }
    m.means.get(w).and_then(|means| means.get(c)).copied()
}

pub fn html(summary: &Summary, frames: &Frames) -> Markup {
    let cols: Vec<_> =
        COLUMNS.iter().copied().filter(|(c, ..)| shown(summary, frames, c)).collect();
    // Each method's effective temporal window: compare flicker at equal windows.
    let temporal = summary.methods.iter().any(|m| m.temporal_window.is_some());
    let hint = |better: &Better| match better {
        Better::Lower => " ↓",
        Better::Higher => " ↑",
        Better::Neither => "",
    };
    html! {
        table id="summary" {
            tr {
                th { "window" } th { "frames" } th { "method" }
                @if temporal {
                    th title="box-filter frames of equal noise variance, nominal (playback::methods::temporal_window)" { "temporal window (frames)" }
                }
                @for (_, name, better) in &cols { th { (name) (hint(better)) } }
            }
            "\n"
            @for w in &summary.windows {
                @let value = |m: usize, c: &str| cell(summary, m, &w.name, c);
                @let bests: Vec<Option<usize>> = cols
                    .iter()
                    .map(|(c, _, better)| {
                        best(&(0..summary.methods.len()).map(|m| value(m, c)).collect::<Vec<_>>(), *better)
                    })
                    .collect();
                @for (mi, m) in summary.methods.iter().enumerate() {
                    tr {
                        td class="m" { (w.name) } td { (w.first) "–" (w.last) } td class="m" { (m.method) }
                        @if temporal {
                            td { (m.temporal_window.map(|v| format!("{v:.1}")).unwrap_or_default()) }
                        }
                        @for (ci, (c, ..)) in cols.iter().enumerate() {
                            @let text = value(mi, c).map(|v| format!("{v:.4}")).unwrap_or_default();
                            @if bests[ci] == Some(mi) {
                                td class="best" title="best in this window" { (text) }
                            } @else {
                                td { (text) }
                            }
                        }
                    }
                    "\n"
                }
            }
        }
        "\n"
    }
}

/// The run's memory: each method's device MiB, the scene's, the device MiB when the world was
/// built and after the last frame, and the process's peak resident MiB.
pub fn memory_html(memory: &Memory) -> Markup {
    let mib =
        |b: Option<f64>| b.map(|b| format!("{:.2}", b / (1024.0 * 1024.0))).unwrap_or_default();
    let mut rows: Vec<(String, Option<f64>)> = memory
        .methods
        .iter()
        .map(|m| (format!("device: {}", m.label), m.device_bytes.map(|b| b as f64)))
        .collect();
    let f = |b: Option<u64>| b.map(|b| b as f64);
    rows.extend(
        [
            ("device: scene", memory.scene_device_bytes.map(|b| b as f64)),
            ("device: all, built", f(memory.device_bytes_built)),
            ("device: all, after the last frame", f(memory.device_bytes_end)),
            ("process: peak resident", f(memory.peak_resident_bytes)),
            ("process: resident after the last frame", f(memory.resident_bytes_end)),
        ]
        .map(|(what, bytes)| (what.to_string(), bytes)),
    );
    html! {
        table id="memory" {
            tr { th { "what" } th { "MiB" } }
            "\n"
            @for (what, bytes) in &rows {
                tr { td class="m" { (what) } td { (mib(*bytes)) } }
                "\n"
            }
        }
        "\n"
    }
}

/// Two runs side by side: per method present in both, the overall mean of each column in A and
/// in B, and B − A (relative, in %), coloured by whether B is better.
pub fn differences_html(a: &Summary, b: &Summary, frames_a: &Frames, frames_b: &Frames) -> Markup {
    let cols: Vec<_> = COLUMNS
        .iter()
        .copied()
        .filter(|(c, ..)| shown(a, frames_a, c) && shown(b, frames_b, c))
        .collect();
    let overall = |s: &Summary, method: &str, c: &str| {
        let m = s.methods.iter().position(|m| m.method == method)?;
        cell(s, m, "overall", c)
    };
    let both = a.methods.iter().filter(|m| b.methods.iter().any(|n| n.method == m.method));
    let rows: Vec<(&str, &str, f64, f64, Option<&str>)> = both
        .flat_map(|m| {
            cols.iter().filter_map(move |(c, name, better)| {
                let (va, vb) = (overall(a, &m.method, c)?, overall(b, &m.method, c)?);
                let class = match (better, (vb - va).partial_cmp(&0.0)) {
                    (Better::Lower, Some(std::cmp::Ordering::Less))
                    | (Better::Higher, Some(std::cmp::Ordering::Greater)) => Some("better"),
                    (Better::Lower, Some(std::cmp::Ordering::Greater))
                    | (Better::Higher, Some(std::cmp::Ordering::Less)) => Some("worse"),
                    _ => None,
                };
                Some((m.method.as_str(), *name, va, vb, class))
            })
        })
        .collect();
    html! {
        table id="differences" {
            tr { th { "method" } th { "column" } th { "A" } th { "B" } th { "B − A" } th { "change" } }
            "\n"
            @for (method, name, va, vb, class) in rows {
                @let d = vb - va;
                @let rel = if va != 0.0 { format!("{:+.1} %", 100.0 * d / va.abs()) } else { String::new() };
                tr {
                    td class="m" { (method) } td class="m" { (name) }
                    td { (format!("{va:.4}")) } td { (format!("{vb:.4}")) }
                    td class=[class] { (format!("{d:+.4}")) } td class=[class] { (rel) }
                }
                "\n"
            }
        }
        "\n"
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    #[test]
    fn best_follows_the_direction_and_ignores_ties_and_gaps() {
        let v = [Some(0.3), None, Some(0.1), Some(0.2)];
        assert_eq!(best(&v, Better::Lower), Some(2));
        assert_eq!(best(&v, Better::Higher), Some(0));
        assert_eq!(best(&v, Better::Neither), None);
        assert_eq!(best(&[Some(0.1), Some(0.1)], Better::Lower), None);
        assert_eq!(best(&[Some(0.1), None], Better::Lower), None);
        assert_eq!(best(&[Some(f64::NAN), Some(1.0), Some(2.0)], Better::Lower), Some(1));
    }
}
