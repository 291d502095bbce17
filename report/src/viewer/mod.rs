//! The viewer at the top of report.html: every method beside the reference, one frame at a
//! time, with a frame slider, play/pause at the scenario's frame rate, exposure on HDR data,
//! FLIP and SMAPE maps, motion vectors, synchronised zoom/pan and the pixel values under the pointer.
//!
//! Frames travel as RGBE planes ([`encoding`]) in one `flickerFrame(frame, {label: base64})` call per
//! frame: inline in the page while all frames together stay under [`EMBED_LIMIT_BYTES`], else
//! in `RUN/viewer/NNNN.js`, which the page loads on demand (a script loads from file://, where
//! the browser refuses fetch()).

pub mod encoding;

use std::collections::HashMap;
use std::path::{Path, PathBuf};

use anyhow::{Context, bail};
use base64::Engine;
use base64::engine::general_purpose::STANDARD;
use maud::{Markup, PreEscaped, html};
use metrics::{Image, load_image};
use rayon::prelude::*;
use serde_json::json;

use crate::page;
use crate::run::{MOTION, Manifest, frame_file};

/// Encoded frames (base64 text) embedded in report.html up to this size; a larger run's frames
/// are linked from `RUN/viewer/`, so the page stays quick to open.
pub const EMBED_LIMIT_BYTES: usize = 32 << 20;

/// The folder, next to report.html, with the linked frames.
pub const LINKED_DIR: &str = "viewer";

/// Width of a panel at the fitted zoom, in CSS pixels.
const PANEL_WIDTH: f64 = 360.0;

const SCRIPT: &str = include_str!("viewer.js");
pub const STYLE: &str = include_str!("viewer.css");

/// The viewer's part of the page.
pub struct Viewer {
    /// Markup, data and script, to be placed at the top of the body.
    pub html: Markup,
    /// Total size of the encoded frames (base64).
    pub encoded_bytes: usize,
    pub linked: bool,
}

/// One panel of the viewer: its caption and where its frames are.
#[derive(Clone, Debug)]
pub struct Panel {
    pub label: String,
    pub run_dir: PathBuf,
    /// The method's frames, or the reference's when `None`.
    pub method: Option<String>,
}

impl Panel {
    /// The reference, then every method, of one run.
    pub fn of_run(run_dir: &Path, methods: &[String]) -> Vec<Panel> {
        let reference =
            Panel { label: "reference".into(), run_dir: run_dir.to_path_buf(), method: None };
        std::iter::once(reference)
            .chain(methods.iter().map(|m| Panel {
                label: m.clone(),
                run_dir: run_dir.to_path_buf(),
                method: Some(m.clone()),
            }))
            .collect()
    }
}

/// Where the viewer's page goes: its folder, and the name of the linked frames' subfolder.
pub struct Output<'a> {
    pub dir: &'a Path,
    pub linked_dir: &'a str,
}

/// One frame's data, as the page receives it (inline in a <script>, or a linked file).
fn chunk_js(frame: u32, entries: &[(String, String)]) -> String {
    let map: serde_json::Map<String, serde_json::Value> =
        entries.iter().map(|(k, v)| (k.clone(), json!(v))).collect();
    format!("flickerFrame({frame},{});\n", page::script_json(&serde_json::Value::Object(map)).0)
}

/// The radiance of a frame: EXR when present, else the PNG made linear.
fn load(run_dir: &Path, method: Option<&str>, frame: u32) -> anyhow::Result<Option<Image>> {
    for ext in ["exr", "png"] {
        let p = frame_file(run_dir, method, frame, ext);
        if p.exists() {
            return load_image(&p).map(Some);
        }
    }
    Ok(None)
}

/// The frame the viewer opens on: the first recorded frame (one with an image on disk) at or
/// after the first scripted event, where the change shows; frame 0 when the run has no event,
/// or none of its frames from the event on was recorded (an interrupted run).
pub fn opening_frame(events: &[crate::run::Event], recorded: &[bool]) -> u32 {
    let Some(first) = events.iter().map(|e| e.frame).min() else { return 0 };
    (first as usize..recorded.len()).find(|&f| recorded[f]).map_or(0, |f| f as u32)
}

/// Builds a viewer of `frame_count` frames over `panels`, or `None` when no frame is on disk.
/// `flip_maps` holds the FLIP map of (frame, panel label) where a reference exists; `manifest`
/// gives the events, reference frames and settings (frame rate, SMAPE's epsilon).
pub fn build(
    out: &Output,
    panels: &[Panel],
    frame_count: u32,
    manifest: &Manifest,
    flip_maps: &HashMap<(u32, String), Vec<f32>>,
) -> anyhow::Result<Option<Viewer>> {
    let size = std::sync::Mutex::new(None::<(u32, u32)>);
    let any_motion = std::sync::atomic::AtomicBool::new(false);
    let any_jod = std::sync::atomic::AtomicBool::new(false);
    let chunks: Vec<Option<String>> = (0..frame_count)
        .into_par_iter()
        .map(|f| {
            let mut entries = Vec::new();
            for p in panels {
                let Some(img) = load(&p.run_dir, p.method.as_deref(), f)? else { continue };
                let mut s = size.lock().unwrap();
                match *s {
                    None => *s = Some((img.width, img.height)),
                    Some(wh) if wh != (img.width, img.height) => {
                        bail!(
                            "{}: frame {f} of {} is {}x{}, other frames are {}x{}",
                            p.run_dir.display(),
                            p.label,
                            img.width,
                            img.height,
                            wh.0,
                            wh.1
                        )
                    }
                    Some(_) => {}
                }
                drop(s);
                entries.push((p.label.clone(), STANDARD.encode(encoding::encode(&img))));
                if let Some(m) = &p.method {
                    let motion =
                        p.run_dir.join("frames").join(m).join(MOTION).join(format!("{f:04}.exr"));
                    if motion.exists() {
                        entries.push((
                            format!("motion:{}", p.label),
                            STANDARD.encode(encoding::encode_motion(&load_image(&motion)?)),
                        ));
                        any_motion.store(true, std::sync::atomic::Ordering::Relaxed);
                    }
                    let jod_map = crate::jod::map_file(&p.run_dir, m, f);
                    if jod_map.exists() {
                        let values: Vec<f32> =
                            load_image(&jod_map)?.rgb.iter().map(|v| v[0]).collect();
                        entries.push((
                            format!("jod:{}", p.label),
                            STANDARD.encode(encoding::encode_map(&values)),
                        ));
                        any_jod.store(true, std::sync::atomic::Ordering::Relaxed);
                    }
                }
                if let Some(map) = flip_maps.get(&(f, p.label.clone())) {
                    entries.push((
                        format!("flip:{}", p.label),
                        STANDARD.encode(encoding::encode_map(map)),
                    ));
                }
            }
            Ok((!entries.is_empty()).then(|| chunk_js(f, &entries)))
        })
        .collect::<anyhow::Result<_>>()?;
    let Some((width, height)) = size.into_inner().unwrap() else { return Ok(None) };
    let encoded_bytes: usize = chunks.iter().flatten().map(String::len).sum();
    let linked = encoded_bytes > EMBED_LIMIT_BYTES;
    let dir = out.dir.join(out.linked_dir);
    if dir.exists() {
        std::fs::remove_dir_all(&dir)
            .with_context(|| format!("cannot remove {}", dir.display()))?;
    }
    if linked {
        std::fs::create_dir_all(&dir)
            .with_context(|| format!("cannot create {}", dir.display()))?;
        for (f, js) in chunks.iter().enumerate() {
            if let Some(js) = js {
                let p = dir.join(format!("{f:04}.js"));
                metrics::atomic::write_bytes(&p, js)?;
            }
        }
    }

    let settings = manifest.raw.get("settings");
    let time_step =
        settings.and_then(|s| s.get("time_step")).and_then(|v| v.as_f64()).filter(|&t| t > 0.0);
    let fps = time_step.map(|t| 1.0 / t).unwrap_or(30.0);
    let smape_epsilon = settings
        .and_then(|s| s.get("smape_epsilon").or(s.get("smape_eps")))
        .and_then(|v| v.as_f64())
        .unwrap_or(0.01);
    let magma: Vec<u8> = (0..256).flat_map(|i| metrics::magma(i as f32 / 255.0)).collect();
    let names: Vec<&str> = panels.iter().map(|p| p.label.as_str()).collect();
    let recorded: Vec<bool> = chunks.iter().map(Option::is_some).collect();
    let start = opening_frame(&manifest.events, &recorded);
    let config = json!({
        "width": width, "height": height, "frames": frame_count, "fps": fps, "labels": names, "start": start,
        "smape_epsilon": smape_epsilon, "motion_steps": encoding::MOTION_STEPS, "linked": linked.then(|| format!("{}/", out.linked_dir)), "magma": magma,
    });

    let last = frame_count.saturating_sub(1);
    let pos = |f: u32| format!("{:.3}", 100.0 * f as f64 / last.max(1) as f64);
    let scale = if (width as f64) < PANEL_WIDTH {
        (PANEL_WIDTH / width as f64).floor()
    } else {
        PANEL_WIDTH / width as f64
    };
    let (vw, vh) = ((width as f64 * scale).round(), (height as f64 * scale).round());
    let mb = |b: usize| b as f64 / (1 << 20) as f64;
    // Settings are f32 in the scenario: print 30 and 0.01, not 29.999998 and 0.009999999776482582.
    let short = |v: f64| format!("{}", (v * 1e4).round() / 1e4);
    let any_motion = any_motion.into_inner();
    let motion_note = if any_motion {
        "Motion vectors: hue gives the direction, brightness the length (brightest = the longest of the panel), values in pixels to the previous frame."
    } else {
        "This run records no motion vectors."
    };
    let html = html! {
        section id="viewer" {
            "\n"
            div class="controls" {
                button id="play" type="button" { "play" }
                div class="timeline" {
                    input type="range" id="frame-slider" min="0" max=(last) value=(start) step="1" aria-label="frame";
                    @for e in &manifest.events {
                        span class="event-mark" data-frame=(e.frame) style={ "left:" (pos(e.frame)) "%" } title={ "frame " (e.frame) ": " (e.label) } { "▼" }
                    }
                    @for &f in &manifest.reference.frames {
                        span class="reference-mark" style={ "left:" (pos(f)) "%" } title={ "reference at frame " (f) } {}
                    }
                }
                span id="frame-label" { "frame " (start) }
                label { "exposure " input type="range" id="exposure" min="-10" max="10" step="0.25" value="0"; }
                span id="exposure-label" { "0 EV" }
                span class="modes" {
                    button type="button" data-mode="image" class="on" { "image" }
                    @if !flip_maps.is_empty() {
                        button type="button" data-mode="flip" { "FLIP map" }
                    }
                    @if any_jod.into_inner() {
                        button type="button" data-mode="jod" title="ColorVideoVDP: 1 − JOD of the pixel / 10" { "JOD map" }
                    }
                    button type="button" data-mode="smape" { "SMAPE to previous frame" }
                    @if any_motion {
                        button type="button" data-mode="motion" { "motion vectors" }
                    }
                }
                button id="fit" type="button" { "fit" }
            }
            "\n"
            div id="panels" {
                @for p in panels {
                    figure class="panel" data-label=(p.label) data-reference=(p.method.is_none()) {
                        div class="view" style={ "width:" (vw) "px;height:" (vh) "px" } {
                            canvas width=(width) height=(height) style={ "width:" (width) "px;height:" (height) "px" } {}
                        }
                        figcaption { (p.label) span class="value" {} }
                    }
                }
            }
            "\n"
            p id="pixel-label" {}
            "\n"
            p class="note" {
                "Plays at " (short(fps)) " frames/s (the scenario's time step). Wheel: zoom, drag: pan, double-click: fit; space: play/pause, arrows: step. "
                "Frames are decoded from RGBE (HDR) in the page; the exposure scales radiance before sRGB. SMAPE maps are computed in the page against the previous frame (ε = " (short(smape_epsilon)) "); "
                "FLIP maps exist at reference frames (grey ticks on the slider), scripted events are marked ▼. " (motion_note) " "
                "Frames: " (format!("{:.1}", mb(encoded_bytes))) " MB, "
                @if linked {
                    "linked from " code { (out.linked_dir) "/" } ": keep the folder next to this page"
                } @else {
                    "embedded in this file"
                }
                " (frames are embedded up to " (format!("{:.0}", mb(EMBED_LIMIT_BYTES))) " MB, linked from " code { (out.linked_dir) "/" } " beyond)."
            }
            "\n"
            script type="application/json" id="flicker-config" { (page::script_json(&config)) }
            "\n"
            script { (PreEscaped("window.flickerChunks={};function flickerFrame(f,d){window.flickerChunks[f]=d;}")) }
            "\n"
            @if !linked {
                @for js in chunks.iter().flatten() {
                    script { (PreEscaped(js)) }
                    "\n"
                }
            }
        }
        "\n"
    };
    Ok(Some(Viewer { html, encoded_bytes, linked }))
}

/// The viewer's script, placed after everything it drives (panels and charts).
pub fn script() -> Markup {
    html! { script { (PreEscaped(SCRIPT)) } "\n" }
}
