//! `flicker bench`: speed, measured side by side in one run and written as a Markdown table.
//! Traversal rays/s (WGSL CWBVH vs obvhs on the CPU, same BVH and rays) and path-tracer frame
//! time per pass. Timings are measurements of this machine, never assertions.

use std::fmt::Write as _;
use std::path::Path;
use std::time::Instant;

use anyhow::{Context, Result};
use render::bvh::{displaced_sphere, traversal_benchmark};
use render::gpu::Gpu;
use render::path_tracer::{PathTracer, PathTracerSettings};
use render::scene::{Instance, Material, SceneDesc};
use sim::{Scenario, Simulation};

pub struct BenchOptions {
    /// Rays per traversal measurement.
    pub rays: u32,
    /// Timed frames per (scene, resolution).
    pub frames: u32,
    pub resolutions: Vec<(u32, u32)>,
    pub frame_scenes: Vec<String>,
}

impl Default for BenchOptions {
    fn default() -> Self {
        Self {
            rays: 1 << 18,
            frames: 5,
            resolutions: vec![(160, 90), (320, 180)],
            frame_scenes: vec!["cornell_box".into(), "courtyard".into()],
        }
    }
}

/// The scene a built-in name builds, at frame 0.
pub fn builtin_scene(name: &str, resolution: (u32, u32)) -> Result<SceneDesc> {
    let text = format!(
        "Scenario(scene: Builtin(\"{name}\"), resolution: ({}, {}), frames: 1, methods: [PathTracing(spp: 1)])",
        resolution.0, resolution.1
    );
    let scenario = Scenario::from_ron(&text, Path::new("<bench>"))?;
    let sim = Simulation::new(&scenario)?;
    Ok(sim.scene().clone())
}

fn mesh_scene(mesh: render::scene::Mesh) -> SceneDesc {
    SceneDesc {
        meshes: vec![mesh],
        materials: vec![Material::default()],
        instances: vec![Instance { mesh: 0, material: 0, transform: glam::Mat4::IDENTITY }],
        environment: glam::Vec3::ONE,
        ..Default::default()
    }
}

pub fn run(opts: &BenchOptions, mut log: impl FnMut(&str)) -> Result<String> {
    let gpu = Gpu::new()?;
    let mut md = String::new();
    writeln!(md, "Adapter: {}; CPU threads: {}\n", gpu.summary, rayon_threads())?;

    writeln!(md, "## BVH traversal (closest hit, {} random rays)\n", opts.rays)?;
    writeln!(md, "| scene | triangles | instances | WGSL Mrays/s | obvhs CPU Mrays/s | WGSL / CPU | hits | WGSL = CPU |")?;
    writeln!(md, "|---|---:|---:|---:|---:|---:|---:|---:|")?;
    let scenes: Vec<(String, SceneDesc)> = vec![
        ("cornell_box".into(), builtin_scene("cornell_box", (64, 36))?),
        ("hairball".into(), builtin_scene("hairball", (64, 36))?),
        ("displaced sphere 100k".into(), mesh_scene(displaced_sphere(100_000, 1))),
    ];
    for (name, scene) in &scenes {
        log(&format!("traversal: {name}"));
        let b = traversal_benchmark(&gpu, scene, opts.rays, 1).with_context(|| format!("traversal benchmark on {name}"))?;
        writeln!(
            md,
            "| {name} | {} | {} | {:.3} | {:.3} | {:.2} | {:.1}% | {:.2}% |",
            b.triangles,
            b.instances,
            b.gpu_rays_per_second / 1e6,
            b.cpu_rays_per_second / 1e6,
            b.gpu_rays_per_second / b.cpu_rays_per_second,
            100.0 * b.hit_fraction,
            100.0 * b.agreement
        )?;
    }

    writeln!(md, "\n## Path tracer frame time ({} frames after one warm-up, 1 spp, max depth 8)\n", opts.frames)?;
    writeln!(md, "| scene | resolution | pass | GPU ms (mean) | CPU ms per frame incl. readback (mean) |")?;
    writeln!(md, "|---|---|---|---:|---:|")?;
    for name in &opts.frame_scenes {
        for &(w, h) in &opts.resolutions {
            log(&format!("frame time: {name} {w}x{h}"));
            let scene = builtin_scene(name, (w, h))?;
            let settings = PathTracerSettings { width: w, height: h, max_depth: 8, rr_start_depth: 3 };
            let mut tracer = PathTracer::new(&gpu, &scene, settings)?;
            tracer.update(&gpu, &scene);
            tracer.render(&gpu, 1, 1, 0)?;
            let mut gpu_ms: Vec<(String, f64, u32)> = Vec::new();
            let start = Instant::now();
            for f in 0..opts.frames {
                let out = tracer.render(&gpu, 1, 1, f + 1)?;
                for t in &out.timings {
                    let entry = match gpu_ms.iter_mut().find(|(p, _, _)| *p == t.pass) {
                        Some(e) => e,
                        None => {
                            gpu_ms.push((t.pass.clone(), 0.0, 0));
                            gpu_ms.last_mut().unwrap()
                        }
                    };
                    // Timestamps where the adapter has them, else per-pass wall time (t.clock).
                    entry.1 += t.ms;
                    entry.2 += 1;
                }
            }
            let cpu_ms = start.elapsed().as_secs_f64() * 1e3 / opts.frames as f64;
            for (pass, sum, n) in &gpu_ms {
                let g = if *n > 0 { format!("{:.2}{}", sum / *n as f64, if gpu.has_timestamps() { "" } else { " (wall)" }) } else { "n/a".into() };
                writeln!(md, "| {name} | {w}x{h} | {pass} | {g} | {cpu_ms:.2} |")?;
            }
        }
    }
    Ok(md)
}

fn rayon_threads() -> usize {
    std::thread::available_parallelism().map(|n| n.get()).unwrap_or(1)
}
