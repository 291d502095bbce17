//! `flicker report --compare RUN_A RUN_B`: two runs (say before and after a change) in one
//! viewer, each method of A beside the same method of B, and one table of their differences.

use std::collections::HashMap;
use std::path::{Path, PathBuf};

use anyhow::{Context, bail};
use maud::html;
use metrics::frames_csv::Frames;

use crate::html::STYLE;
use crate::images::write_frame_images;
use crate::page;
use crate::run::Manifest;
use crate::summary::summarize;
use crate::viewer::{self, Panel};
use crate::window::DEFAULT_WINDOW;

/// The methods of a run, as report.html lists them.
fn methods(manifest: &Manifest, frames: &Frames) -> Vec<String> {
    if manifest.methods.is_empty() { frames.methods() } else { manifest.methods.clone() }
}

/// Writes the comparison page to `out` (its linked frames, if any, to `<stem>_viewer/` beside it).
/// Each run's FLIP maps and crops are (re)written to its `charts/`, as `flicker report` does.
pub fn write_comparison(run_a: &Path, run_b: &Path, out: &Path) -> anyhow::Result<PathBuf> {
    let (ma, mb) = (Manifest::load(run_a)?, Manifest::load(run_b)?);
    let (fa, fb) = (Frames::load(run_a)?, Frames::load(run_b)?);
    if let (Some(ra), Some(rb)) = (ma.resolution, mb.resolution)
        && ra != rb
    {
        bail!(
            "{} is {}x{} and {} is {}x{}: the viewer compares runs of one resolution",
            run_a.display(),
            ra[0],
            ra[1],
            run_b.display(),
            rb[0],
            rb[1]
        );
    }
    let (methods_a, methods_b) = (methods(&ma, &fa), methods(&mb, &fb));
    // A's reference, then each method of A beside the same method of B; methods only in one run last.
    let mut panels =
        vec![Panel { label: "reference".into(), run_dir: run_a.to_path_buf(), method: None }];
    let mut flip_maps = HashMap::new();
    for (tag, dir, manifest, list) in [("A", run_a, &ma, &methods_a), ("B", run_b, &mb, &methods_b)]
    {
        for fi in write_frame_images(dir, manifest, list)? {
            for m in fi.methods {
                flip_maps.insert((fi.frame, format!("{tag}: {}", m.method)), m.flip);
            }
        }
    }
    let panel = |tag: &str, dir: &Path, m: &str| Panel {
        label: format!("{tag}: {m}"),
        run_dir: dir.to_path_buf(),
        method: Some(m.to_string()),
    };
    for m in &methods_a {
        panels.push(panel("A", run_a, m));
        if methods_b.contains(m) {
            panels.push(panel("B", run_b, m));
        }
    }
    panels
        .extend(methods_b.iter().filter(|m| !methods_a.contains(m)).map(|m| panel("B", run_b, m)));

    let out_dir = out.parent().filter(|p| !p.as_os_str().is_empty()).unwrap_or(Path::new("."));
    std::fs::create_dir_all(out_dir)
        .with_context(|| format!("cannot create {}", out_dir.display()))?;
    let stem = out.file_stem().and_then(|s| s.to_str()).unwrap_or("compare");
    let linked_dir = format!("{stem}_viewer");
    let frame_count = ma.frame_count(&fa).max(mb.frame_count(&fb));
    let viewer = viewer::build(
        &viewer::Output { dir: out_dir, linked_dir: &linked_dir },
        &panels,
        frame_count,
        &ma,
        &flip_maps,
    )?;

    let title = format!("flicker: {} vs {}", run_a.display(), run_b.display());
    let (mut sa, mut sb) =
        (summarize(&ma, &fa, DEFAULT_WINDOW), summarize(&mb, &fb, DEFAULT_WINDOW));
    crate::summary::add_jod_from_file(&mut sa, run_a);
    crate::summary::add_jod_from_file(&mut sb, run_b);
    let body = html! {
        h1 { (title) } "\n"
        table id="runs" {
            tr { th { "run" } th { "folder" } th { "scenario" } th { "commit" } th { "frames" } th { "methods" } }
            "\n"
            @for (tag, dir, m, list) in [("A", run_a, &ma, &methods_a), ("B", run_b, &mb, &methods_b)] {
                tr {
                    td class="m" { (tag) }
                    td class="m" { (dir.display().to_string()) }
                    td class="m" { (m.scenario) }
                    td class="m" { code { (m.raw.get("commit").and_then(|c| c.as_str()).unwrap_or("")) } }
                    td { (m.frames.map(|f| f.to_string()).unwrap_or_default()) }
                    td class="m" { (list.join(", ")) }
                }
                "\n"
            }
        }
        "\n"
        @match &viewer {
            Some(v) => (v.html),
            None => { p { "Neither run has frames on disk: nothing to view." } "\n" },
        }
        h2 { "Differences" }
        p { "Overall means of each method found in both runs; green where B is better, red where it is worse." }
        "\n"
        (crate::table::differences_html(&sa, &sb, &fa, &fb))
        @if viewer.is_some() {
            (viewer::script())
        }
    };
    let h = page::document(&title, &format!("{STYLE}{}", viewer::STYLE), body);
    metrics::atomic::write_bytes(out, h)?;
    Ok(out.to_path_buf())
}
