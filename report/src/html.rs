//! report.html: one self-contained page per run (every image inlined as a data: URI).

use std::fmt::Write as _;
use std::path::{Path, PathBuf};

use anyhow::Context;

use crate::base64::data_uri;
use crate::charts::build::write_charts;
use crate::images::write_frame_images;
use crate::run::{Frames, Manifest};
use crate::summary::{DEFAULT_WINDOW, summarize};

fn esc(s: &str) -> String {
    s.replace('&', "&amp;").replace('<', "&lt;").replace('>', "&gt;").replace('"', "&quot;")
}

fn png_uri(path: &Path) -> anyhow::Result<String> {
    let bytes = std::fs::read(path).with_context(|| format!("cannot read {}", path.display()))?;
    Ok(data_uri("image/png", &bytes))
}

/// Columns of the summary table, when present.
const TABLE_COLUMNS: [(&str, &str); 10] = [
    ("flip", "FLIP"),
    ("smape", "SMAPE"),
    ("smape_reprojected", "SMAPE (reproj.)"),
    ("psnr", "PSNR dB"),
    ("rel_mse", "rel. MSE"),
    ("gpu_ms_total", "GPU ms"),
    ("wall_ms_total", "pass wall ms"),
    ("cpu_ms", "CPU ms"),
    ("rays", "rays"),
    ("shaded", "shaded paths"),
];

const STYLE: &str = "body{font-family:sans-serif;margin:24px;max-width:1500px;color:#222}\
table{border-collapse:collapse;margin:8px 0 20px}td,th{border:1px solid #ccc;padding:3px 8px;text-align:right}\
th{background:#f3f3f3}td.m{text-align:left}.charts{display:flex;flex-wrap:wrap}.charts img{margin:4px;border:1px solid #ddd;max-width:100%;height:auto}\
figure{display:inline-block;margin:6px;vertical-align:top}figcaption{font-size:12px;text-align:center}\
img.px{image-rendering:pixelated}pre{background:#f7f7f7;padding:10px;overflow:auto;font-size:12px}";

/// Writes RUN/report.html (and the charts and error maps it shows); returns its path.
pub fn write_report(run_dir: &Path) -> anyhow::Result<PathBuf> {
    let manifest = Manifest::load(run_dir)?;
    let frames = Frames::load(run_dir)?;
    let summary = summarize(&manifest, &frames, DEFAULT_WINDOW);
    let charts = write_charts(run_dir, &manifest, &frames)?;
    let methods = if manifest.methods.is_empty() { frames.methods() } else { manifest.methods.clone() };
    let frame_images = write_frame_images(run_dir, &manifest, &methods)?;

    let mut h = String::new();
    let title = format!("flicker run: {}", manifest.scenario);
    let _ = write!(h, "<!DOCTYPE html>\n<html lang=\"en\"><head><meta charset=\"utf-8\"><title>{}</title><style>{STYLE}</style></head><body>\n", esc(&title));
    let _ = writeln!(h, "<h1>{}</h1>", esc(&title));
    let raw = &manifest.raw;
    let field = |k: &str| raw.get(k).map(|v| v.to_string().trim_matches('"').to_string()).unwrap_or_default();
    let _ = writeln!(
        h,
        "<p>commit <code>{}</code> · seed {} · resolution {} · {} frames · methods: {}</p>",
        esc(&field("commit")),
        esc(&field("seed")),
        esc(&field("resolution")),
        esc(&field("frames")),
        esc(&methods.join(", "))
    );
    if !manifest.events.is_empty() {
        let ev: Vec<String> = manifest.events.iter().map(|e| format!("frame {}: {}", e.frame, esc(&e.label))).collect();
        let _ = writeln!(h, "<p>Events: {}</p>", ev.join(" · "));
    }

    // Summary table: one block of rows per window.
    let _ = writeln!(h, "<h2>Summary</h2><p>Means per method over frame windows (transient = {} frames after an event).</p>", summary.window_frames);
    let cols: Vec<(&str, &str)> = TABLE_COLUMNS.iter().copied().filter(|(c, _)| frames.column(c).is_some_and(|i| frames.has_data(i))).collect();
    let _ = write!(h, "<table id=\"summary\"><tr><th>window</th><th>frames</th><th>method</th>");
    for (_, name) in &cols {
        let _ = write!(h, "<th>{name}</th>");
    }
    h.push_str("</tr>\n");
    for w in &summary.windows {
        for m in &summary.methods {
            let _ = write!(h, "<tr><td class=\"m\">{}</td><td>{}–{}</td><td class=\"m\">{}</td>", esc(&w.name), w.first, w.last, esc(&m.method));
            for (c, _) in &cols {
                let v = m.means.get(&w.name).and_then(|means| means.get(*c));
                let _ = write!(h, "<td>{}</td>", v.map(|v| format!("{v:.4}")).unwrap_or_default());
            }
            h.push_str("</tr>\n");
        }
    }
    h.push_str("</table>\n");

    h.push_str("<h2>Charts</h2><div class=\"charts\">\n");
    for c in &charts {
        let _ = writeln!(h, "<img class=\"chart\" src=\"{}\" alt=\"{}\" width=\"720\" height=\"400\">", data_uri("image/svg+xml", c.svg.as_bytes()), esc(&c.title));
    }
    h.push_str("</div>\n");

    for fi in &frame_images {
        let _ = writeln!(h, "<h2>Frame {}</h2><div>", fi.frame);
        let _ = writeln!(h, "<figure><img class=\"px frame\" src=\"{}\" alt=\"reference\"><figcaption>reference</figcaption></figure>", png_uri(&fi.reference)?);
        for m in &fi.methods {
            let _ = writeln!(
                h,
                "<figure><img class=\"px frame\" src=\"{uri}\" alt=\"{name}\"><figcaption>{name}</figcaption></figure>",
                uri = png_uri(&m.image)?,
                name = esc(&m.method)
            );
        }
        h.push_str("</div><div>");
        for m in &fi.methods {
            let _ = writeln!(
                h,
                "<figure><img class=\"px map\" src=\"{uri}\" alt=\"FLIP map {name}\"><figcaption>FLIP {name}: {mean:.4}</figcaption></figure>",
                uri = png_uri(&m.flip_map)?,
                name = esc(&m.method),
                mean = m.flip_mean
            );
        }
        h.push_str("</div>\n");
        for (region, path) in &fi.crops {
            let _ = writeln!(
                h,
                "<figure><img class=\"px crop\" src=\"{uri}\" alt=\"crops {name}\"><figcaption>{name}: reference, {list} (FLIP maps below)</figcaption></figure>",
                uri = png_uri(path)?,
                name = esc(region),
                list = esc(&fi.methods.iter().map(|m| m.method.as_str()).collect::<Vec<_>>().join(", "))
            );
        }
    }
    let _ = writeln!(h, "<h2>Manifest</h2><pre>{}</pre>", esc(&serde_json::to_string_pretty(raw)?));
    h.push_str("</body></html>\n");
    let path = run_dir.join("report.html");
    std::fs::write(&path, h).with_context(|| format!("cannot write {}", path.display()))?;
    Ok(path)
}
