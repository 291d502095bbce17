//! `flicker bench`'s device memory table: each shipped method's world built (no frame played)
//! at the bench's resolutions, the device bytes its state allocated (`playback::memory`).

use std::fmt::Write as _;
use std::path::Path;

use anyhow::Result;
use frame::run_folder::RunFolder;
use indicatif::ProgressBar;
use playback::memory::{MethodMemory, RunMemory};
use playback::play::FrameWorld;
use playback::scenario::{Overrides, RunSpec};
use render::gpu::Gpu;
use serde::Serialize;

const MIB: f64 = 1024.0 * 1024.0;

fn mib(bytes: Option<i64>) -> String {
    bytes.map_or("n/a".into(), |b| format!("{:.2}", b as f64 / MIB))
}

/// The worlds the bench measures: each shipped method at its defaults where a scene of the
/// right kind needs no more (subsurface and media methods get one), one instance each.
const BENCH_WORLDS: [(&str, &str, &str); 3] = [
    (
        "cornell_box",
        "methods: [PathTracing(spp: 1), Taa(), HashCache(), SampleCache(), Termination(), Nirc(spp: 1)]",
        "",
    ),
    (
        "sss_sphere",
        "methods: [Sss(variant: Adaptive)]",
        "materials: [(material: \"skin\", subsurface: (dmfp: (0.12, 0.05, 0.025)))],",
    ),
    (
        "cornell_box",
        "methods: [VolumeTransmittance(estimator: RatioTracking, spp: 1), VolumePath(spp: 1)]",
        "media: [(name: \"cloud\", kind: Cloud(octaves: 5, frequency: 3.0, seed: 7), box_min: (-1, -1, -1), box_max: (1, 1, 1), sigma_t: 6.0, resolution: (96, 96, 96), albedo: (0.9, 0.9, 0.9))],",
    ),
];

/// One row of the bench's memory table.
#[derive(Clone, Debug, Serialize)]
pub struct BenchRow {
    pub scene: String,
    pub width: u32,
    pub height: u32,
    pub scene_device_bytes: Option<i64>,
    pub methods: Vec<MethodMemory>,
}

/// Device bytes per method and scene at each of `resolutions` (each world built, no frame
/// played): a Markdown table and its rows. `scratch` is a folder for the worlds' caches, created
/// and removed here.
pub fn table(resolutions: &[(u32, u32)], scratch: &Path) -> Result<(String, Vec<BenchRow>)> {
    std::fs::create_dir_all(scratch)?;
    let rows = bench_rows(resolutions, scratch);
    std::fs::remove_dir_all(scratch).ok();
    let rows = rows?;
    let mut md = String::from(
        "## Device memory per method (buffers and textures its state allocates, MiB)\n\n| scene | resolution | method | MiB | scene's MiB |\n|---|---|---|---:|---:|\n",
    );
    for r in &rows {
        for m in &r.methods {
            writeln!(
                md,
                "| {} | {}x{} | {} | {} | {} |",
                r.scene,
                r.width,
                r.height,
                m.label,
                mib(m.device_bytes),
                mib(r.scene_device_bytes)
            )?;
        }
    }
    if let Some(nirc) = rows.iter().flat_map(|r| &r.methods).find(|m| m.label.starts_with("nirc")) {
        let (w, h) = resolutions[0];
        writeln!(
            md,
            "\n## One NIRC cache at the defaults ({}, {w}x{h}): its buffers and textures\n\n| buffer | MiB |\n|---|---:|",
            nirc.label
        )?;
        for (name, bytes) in &nirc.buffers {
            writeln!(md, "| {name} | {:.2} |", *bytes as f64 / MIB)?;
        }
        writeln!(md, "| total | {} |", mib(nirc.device_bytes))?;
    }
    Ok((md, rows))
}

fn bench_rows(resolutions: &[(u32, u32)], scratch: &Path) -> Result<Vec<BenchRow>> {
    let mut rows = Vec::new();
    for &(w, h) in resolutions {
        for (scene, methods, extra) in BENCH_WORLDS {
            let text = format!(
                "Scenario(scene: Builtin(\"{scene}\"), resolution: ({w}, {h}), frames: 1, {methods}, reference: (spp: 0, frames: None), {extra})"
            );
            let scenario = sim::Scenario::from_ron(&text, &scratch.join("memory.ron"))?;
            let spec = RunSpec::from_scenario(scenario, &Overrides::default())?;
            let frames = FrameWorld::build(
                &spec,
                Gpu::new()?,
                scratch.join("cache"),
                RunFolder::new(scratch.join("run")),
                ProgressBar::hidden(),
            )?;
            let memory = frames.world.resource::<RunMemory>();
            rows.push(BenchRow {
                scene: scene.into(),
                width: w,
                height: h,
                scene_device_bytes: memory.scene_device_bytes,
                methods: memory.methods.clone(),
            });
        }
    }
    Ok(rows)
}
