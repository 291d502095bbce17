//! report.html: one page per run. The viewer comes first (frames, maps, pixel values), then
//! speed against accuracy, the summary table, the charts against frame (with a cursor at the
//! viewer's frame), region crops and the manifest. Every image is inlined as a data: URI; the
//! viewer's frames are inlined up to a size threshold (see `viewer`).

use std::collections::HashMap;
use std::fmt::Write as _;
use std::path::{Path, PathBuf};

use anyhow::Context;
use metrics::frames_csv::Frames;

use crate::charts::build::{WrittenChart, write_charts};
use crate::data_uri::data_uri;
use crate::images::write_frame_images;
use crate::run::Manifest;
use crate::summary::{DEFAULT_WINDOW, summarize};
use crate::{table, viewer};

pub fn esc(s: &str) -> String {
    s.replace('&', "&amp;").replace('<', "&lt;").replace('>', "&gt;").replace('"', "&quot;")
}

fn png_uri(path: &Path) -> anyhow::Result<String> {
    let bytes = std::fs::read(path).with_context(|| format!("cannot read {}", path.display()))?;
    Ok(data_uri("image/png", &bytes))
}

pub const STYLE: &str = "body{font-family:sans-serif;margin:24px;max-width:1600px;color:#222}\
table{border-collapse:collapse;margin:8px 0 20px}td,th{border:1px solid #ccc;padding:3px 8px;text-align:right}\
th{background:#f3f3f3}td.m{text-align:left}td.best{font-weight:bold;background:#e3f1e3}td.better{background:#e3f1e3}td.worse{background:#f8e0e0}\
.charts{display:grid;grid-template-columns:repeat(auto-fill,minmax(520px,1fr));gap:8px}\
.chart{position:relative;margin:0}.chart img{display:block;width:100%;height:auto;border:1px solid #ddd}\
.chart .cursor{position:absolute;top:0;bottom:0;border-left:2px solid rgba(0,0,0,.55);pointer-events:none}\
figure{display:inline-block;margin:6px;vertical-align:top}figcaption{font-size:12px;text-align:center}\
img.px{image-rendering:pixelated}pre{background:#f7f7f7;padding:10px;overflow:auto;font-size:12px}";

/// A chart as an image; charts against frame carry where frames lie (for the cursor).
fn chart_html(c: &WrittenChart) -> String {
    let img = format!(
        "<img class=\"chart-img\" src=\"{}\" alt=\"{}\">",
        data_uri("image/svg+xml", c.svg.as_bytes()),
        esc(&c.title)
    );
    match c.frame_axis {
        Some(m) => format!(
            "<figure class=\"chart\" data-f0=\"{}\" data-f1=\"{}\" data-x0=\"{}\" data-x1=\"{}\" data-w=\"{}\">{img}<div class=\"cursor\"></div></figure>\n",
            m.v0,
            m.v1,
            m.x0,
            m.x1,
            crate::charts::WIDTH
        ),
        None => format!("<figure class=\"chart\">{img}</figure>\n"),
    }
}

/// Writes RUN/report.html (and the charts and error maps it shows); returns its path.
pub fn write_report(run_dir: &Path) -> anyhow::Result<PathBuf> {
    let manifest = Manifest::load(run_dir)?;
    let frames = Frames::load(run_dir)?;
    let mut summary = summarize(&manifest, &frames, DEFAULT_WINDOW);
    crate::summary::add_jod_from_file(&mut summary, run_dir);
    let charts = write_charts(run_dir, &manifest, &frames)?;
    let methods =
        if manifest.methods.is_empty() { frames.methods() } else { manifest.methods.clone() };
    let frame_images = write_frame_images(run_dir, &manifest, &methods)?;
    let flip_maps: HashMap<(u32, String), Vec<f32>> = frame_images
        .iter()
        .flat_map(|fi| {
            fi.methods.iter().map(move |m| ((fi.frame, m.method.clone()), m.flip.clone()))
        })
        .collect();
    let frame_count = manifest.frame_count(&frames);
    let out = viewer::Output { dir: run_dir, linked_dir: viewer::LINKED_DIR };
    let viewer = viewer::build(
        &out,
        &viewer::Panel::of_run(run_dir, &methods),
        frame_count,
        &manifest,
        &flip_maps,
    )?;

    let mut h = String::new();
    let title = format!("flicker run: {}", manifest.scenario);
    let _ = write!(
        h,
        "<!DOCTYPE html>\n<html lang=\"en\"><head><meta charset=\"utf-8\"><title>{}</title><style>{STYLE}{}</style></head><body>\n",
        esc(&title),
        viewer::STYLE
    );
    let _ = writeln!(h, "<h1>{}</h1>", esc(&title));
    let raw = &manifest.raw;
    let field = |k: &str| {
        raw.get(k).map(|v| v.to_string().trim_matches('"').to_string()).unwrap_or_default()
    };
    let _ = writeln!(
        h,
        "<p>commit <code>{}</code> · seed {} · resolution {} · {} frames · methods: {}</p>",
        esc(&field("commit")),
        esc(&field("seed")),
        esc(&field("resolution")),
        esc(&field("frames")),
        esc(&methods.join(", "))
    );
    if let Some(status) = raw.get("status").and_then(|s| s.as_str()).filter(|s| *s != "complete") {
        let last = raw.get("last_complete_frame").and_then(|f| f.as_u64());
        let _ = writeln!(
            h,
            "<p class=\"incomplete\"><strong>Incomplete run</strong> ({}): {}. Continue it with <code>flicker run --resume</code>.</p>",
            esc(status),
            last.map_or("no recorded frame was written".into(), |f| format!(
                "frames 0 to {f} of {} were written",
                field("frames")
            ))
        );
    }
    if !manifest.events.is_empty() {
        let ev: Vec<String> = manifest
            .events
            .iter()
            .map(|e| format!("frame {}: {}", e.frame, esc(&e.label)))
            .collect();
        let _ = writeln!(h, "<p>Events: {}</p>", ev.join(" · "));
    }
    match &viewer {
        Some(v) => h.push_str(&v.html),
        None => h.push_str("<p>No frames of this run are on disk: nothing to view.</p>\n"),
    }

    let (speed, per_frame): (Vec<&WrittenChart>, Vec<&WrittenChart>) =
        charts.iter().partition(|c| c.stem.starts_with("speed_vs_"));
    if !speed.is_empty() {
        h.push_str("<h2>Speed vs accuracy</h2><div class=\"charts\">\n");
        speed.iter().for_each(|c| h.push_str(&chart_html(c)));
        h.push_str("</div>\n");
    }
    let _ = writeln!(
        h,
        "<h2>Summary</h2><p>Means per method over frame windows (transient = {} frames after an event); the best method of each column is marked (↓ lower is better, ↑ higher).</p>",
        summary.window_frames
    );
    h.push_str(&table::html(&summary, &frames));
    if let Some(memory) = &summary.memory {
        h.push_str("<h2>Memory</h2><p>Device memory of buffers and textures (wgpu's allocator report) and the process's peak resident memory over the frames.</p>\n");
        h.push_str(&table::memory_html(memory));
    }
    if !per_frame.is_empty() {
        h.push_str("<h2>Charts</h2><div class=\"charts\">\n");
        per_frame.iter().for_each(|c| h.push_str(&chart_html(c)));
        h.push_str("</div>\n");
    }

    let crops: Vec<_> =
        frame_images.iter().flat_map(|fi| fi.crops.iter().map(move |c| (fi, c))).collect();
    let any_crops = !crops.is_empty();
    if any_crops {
        h.push_str("<h2>Regions at reference frames</h2><div>\n");
    }
    for (fi, (region, path)) in crops {
        let _ = writeln!(
            h,
            "<figure><img class=\"px crop\" src=\"{uri}\" alt=\"crops {name} frame {frame}\"><figcaption>frame {frame}, {name}: reference, {list} (FLIP maps below)</figcaption></figure>",
            uri = png_uri(path)?,
            name = esc(region),
            frame = fi.frame,
            list =
                esc(&fi.methods.iter().map(|m| m.method.as_str()).collect::<Vec<_>>().join(", "))
        );
    }
    if any_crops {
        h.push_str("</div>\n");
    }
    let _ = writeln!(h, "<h2>Manifest</h2><pre>{}</pre>", esc(&serde_json::to_string_pretty(raw)?));
    if viewer.is_some() {
        h.push_str(&viewer::script());
    }
    h.push_str("</body></html>\n");
    let path = run_dir.join("report.html");
    metrics::atomic::write_bytes(&path, h)?;
    Ok(path)
}
