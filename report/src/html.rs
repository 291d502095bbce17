//! report.html: one page per run. The viewer comes first (frames, maps, pixel values), then
//! speed against accuracy, the summary table, the charts against frame (with a cursor at the
//! viewer's frame), region crops and the manifest. Every image is inlined as a data: URI; the
//! viewer's frames are inlined up to a size threshold (see `viewer`).

use std::collections::HashMap;
use std::path::{Path, PathBuf};

use anyhow::Context;
use maud::{Markup, html};
use metrics::frames_csv::Frames;

use crate::charts::build::{WrittenChart, write_charts};
use crate::data_uri::data_uri;
use crate::images::write_frame_images;
use crate::run::Manifest;
use crate::summary::summarize;
use crate::window::DEFAULT_WINDOW;
use crate::{page, table, viewer};

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
fn chart_html(c: &WrittenChart) -> Markup {
    let img = html! {
        img class="chart-img" src=(data_uri("image/svg+xml", c.svg.as_bytes())) alt=(c.title);
    };
    html! {
        @match c.frame_axis {
            Some(m) => {
                figure class="chart" data-f0=(m.v0) data-f1=(m.v1) data-x0=(m.x0) data-x1=(m.x1) data-w=(crate::charts::WIDTH) {
                    (img) div class="cursor" {}
                }
            }
            None => figure class="chart" { (img) },
        }
        "\n"
    }
}

/// Writes RUN/report.html (and the charts and error maps it shows, the methods' `declared`
/// charts among them); returns its path.
pub fn write_report(
    run_dir: &Path,
    declared: &[crate::declared::MethodChart],
) -> anyhow::Result<PathBuf> {
    let manifest = Manifest::load(run_dir)?;
    let frames = Frames::load(run_dir)?;
    let mut summary = summarize(&manifest, &frames, DEFAULT_WINDOW);
    crate::summary::add_jod_from_file(&mut summary, run_dir);
    let charts = write_charts(run_dir, &manifest, &frames, declared)?;
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

    let title = format!("flicker run: {}", manifest.scenario);
    let raw = &manifest.raw;
    let field = |k: &str| {
        raw.get(k).map(|v| v.to_string().trim_matches('"').to_string()).unwrap_or_default()
    };
    let status = raw.get("status").and_then(|s| s.as_str()).filter(|s| *s != "complete");
    let written = |last: Option<u64>| {
        last.map_or("no recorded frame was written".into(), |f| {
            format!("frames 0 to {f} of {} were written", field("frames"))
        })
    };
    let (speed, per_frame): (Vec<&WrittenChart>, Vec<&WrittenChart>) =
        charts.iter().partition(|c| c.stem.starts_with("speed_vs_"));
    let crops: Vec<_> = frame_images
        .iter()
        .flat_map(|fi| fi.crops.iter().map(move |(region, path)| (fi, region, path)))
        .map(|(fi, region, path)| Ok((fi, region, png_uri(path)?)))
        .collect::<anyhow::Result<_>>()?;
    let manifest_text = serde_json::to_string_pretty(raw)?;
    let body = html! {
        h1 { (title) } "\n"
        p {
            "commit " code { (field("commit")) } " · seed " (field("seed")) " · resolution " (field("resolution"))
            " · " (field("frames")) " frames · methods: " (methods.join(", "))
        }
        "\n"
        @if let Some(status) = status {
            p class="incomplete" {
                strong { "Incomplete run" } " (" (status) "): "
                (written(raw.get("last_complete_frame").and_then(|f| f.as_u64())))
                ". Continue it with " code { "flicker run --resume" } "."
            }
            "\n"
        }
        @if !manifest.events.is_empty() {
            p {
                "Events: "
                @for (i, e) in manifest.events.iter().enumerate() {
                    @if i > 0 { " · " }
                    "frame " (e.frame) ": " (e.label)
                }
            }
            "\n"
        }
        @match &viewer {
            Some(v) => (v.html),
            None => { p { "No frames of this run are on disk: nothing to view." } "\n" },
        }
        @if !speed.is_empty() {
            h2 { "Speed vs accuracy" }
            div class="charts" { "\n" @for c in &speed { (chart_html(c)) } }
            "\n"
        }
        h2 { "Summary" }
        p {
            "Means per method over frame windows (transient = " (summary.window_frames)
            " frames after an event); the best method of each column is marked (↓ lower is better, ↑ higher)."
        }
        "\n"
        (table::html(&summary, &frames))
        @if let Some(memory) = &summary.memory {
            h2 { "Memory" }
            p { "Device memory of buffers and textures (wgpu's allocator report) and the process's peak resident memory over the frames." }
            "\n"
            (table::memory_html(memory))
        }
        @if !per_frame.is_empty() {
            h2 { "Charts" }
            div class="charts" { "\n" @for c in &per_frame { (chart_html(c)) } }
            "\n"
        }
        @if !crops.is_empty() {
            h2 { "Regions at reference frames" }
            div {
                "\n"
                @for (fi, region, uri) in &crops {
                    @let list = fi.methods.iter().map(|m| m.method.as_str()).collect::<Vec<_>>().join(", ");
                    figure {
                        img class="px crop" src=(uri) alt={ "crops " (region) " frame " (fi.frame) };
                        figcaption { "frame " (fi.frame) ", " (region) ": reference, " (list) " (FLIP maps below)" }
                    }
                    "\n"
                }
            }
            "\n"
        }
        h2 { "Manifest" } pre { (manifest_text) } "\n"
        @if viewer.is_some() {
            (viewer::script())
        }
    };
    let h = page::document(&title, &format!("{STYLE}{}", viewer::STYLE), body);
    let path = run_dir.join("report.html");
    metrics::atomic::write_bytes(&path, h)?;
    Ok(path)
}
