//! `flicker bench`: speed, measured side by side in one run and written as a Markdown table.
//! Traversal rays/s (WGSL CWBVH vs obvhs on the CPU, same BVH and rays) and path-tracer frame
//! time per pass. Timings are measurements of this machine, never assertions.

use std::fmt::Write as _;
use std::time::Instant;

use crate::mitsuba::{self, lambertian_cornell_box};
use anyhow::{Context, Result};
use playback::scenario::builtin_scene;
use render::bvh::displaced_sphere;
use render::gpu::Gpu;
use render::path_tracer::{PathTracer, PathTracerSettings};
use render::scene::{Instance, Material, SceneDesc};
use render::scene_gpu::SceneGpu;

use crate::traversal::{PAIRED_ROUNDS, median, range, traversal_benchmark};
use crate::wavefront::{Kernel, KernelTimes, Wavefront};

pub struct BenchOptions {
    /// Rays per traversal measurement.
    pub rays: u32,
    /// Samples per pixel of the reference path-tracing measurement (64x64 Cornell box).
    pub reference_spp: u32,
    /// Timed frames per (scene, resolution).
    pub frames: u32,
    pub resolutions: Vec<(u32, u32)>,
    pub frame_scenes: Vec<String>,
}

impl Default for BenchOptions {
    fn default() -> Self {
        Self {
            rays: 1 << 18,
            reference_spp: 256,
            frames: 5,
            resolutions: vec![(160, 90), (320, 180)],
            frame_scenes: vec!["cornell_box".into(), "courtyard".into()],
        }
    }
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

/// The bench's Markdown table and the same numbers as JSON (`flicker bench --json`).
pub struct BenchReport {
    pub markdown: String,
    pub json: serde_json::Value,
}

/// One traversal measurement (a row of the table and of the JSON's `traversal`).
#[derive(serde::Serialize)]
struct TraversalRow {
    scene: String,
    triangles: u64,
    wgsl_mrays_per_s: f64,
    cpu_mrays_per_s: f64,
    /// The median over paired rounds of WGSL over obvhs (crate::traversal::PAIRED_ROUNDS).
    traversal_ratio_vs_obvhs: f64,
    /// Each round's ratio, in order.
    paired_ratios: Vec<f64>,
    /// The same rays sorted for coherence (crate::ray_order).
    wgsl_sorted_mrays_per_s: f64,
    cpu_sorted_mrays_per_s: f64,
    /// WGSL on sorted rays over WGSL on the same rays in random order.
    wgsl_sorted_speedup: f64,
    /// The same random rays through obvhs's binary BVHs (crate::bvh2_geometry::Bvh2Geometry).
    wgsl_bvh2_mrays_per_s: f64,
    /// BVH2 over CWBVH, WGSL, same rays.
    bvh2_vs_cwbvh: f64,
    /// obvhs's own CPU traversal of those BVH2s, and its ratio to obvhs's CWBVH traversal.
    cpu_bvh2_mrays_per_s: f64,
    cpu_bvh2_vs_cwbvh: f64,
    /// Fraction of rays whose BVH2 hit is the CPU's (instance and primitive).
    bvh2_agreement: f64,
}

/// One path-tracer frame measurement (the JSON's `frames`).
#[derive(serde::Serialize)]
struct FrameRow {
    scene: String,
    width: u32,
    height: u32,
    /// Mean GPU ms per pass.
    gpu_ms: std::collections::BTreeMap<String, f64>,
    rays_per_frame: f64,
    /// The frame's rays over its GPU time (all passes).
    frame_mrays_per_s: f64,
}

pub fn run(opts: &BenchOptions, mut log: impl FnMut(&str)) -> Result<BenchReport> {
    let gpu = Gpu::new()?;
    let mut md = String::new();
    let mut traversal_rows: Vec<TraversalRow> = Vec::new();
    let mut frame_rows: Vec<FrameRow> = Vec::new();
    writeln!(md, "Adapter: {}; CPU threads: {}\n", gpu.summary, rayon_threads())?;
    log("warm-up");
    warm_up(&gpu)?;

    writeln!(md, "## BVH traversal (closest hit, {} random rays)\n", opts.rays)?;
    writeln!(
        md,
        "| scene | triangles | instances | stack entries | WGSL Mrays/s | obvhs CPU Mrays/s | WGSL / CPU (median of {} paired rounds) | rounds: lowest, highest | sorted: WGSL Mrays/s | sorted: CPU Mrays/s | sorted / random, WGSL | BVH2: WGSL Mrays/s | BVH2 / CWBVH, WGSL | BVH2 / CWBVH, obvhs CPU | hits | WGSL = CPU | BVH2 = CPU |",
        PAIRED_ROUNDS
    )?;
    writeln!(
        md,
        "|---|---:|---:|---:|---:|---:|---:|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|"
    )?;
    let scenes: Vec<(String, SceneDesc)> = vec![
        ("cornell_box".into(), builtin_scene("cornell_box", (64, 36))?),
        ("hairball".into(), builtin_scene("hairball", (64, 36))?),
        ("displaced sphere 100k".into(), mesh_scene(displaced_sphere(100_000, 1))),
    ];
    for (name, scene) in &scenes {
        log(&format!("traversal: {name}"));
        let b = traversal_benchmark(&gpu, scene, opts.rays, 1)
            .with_context(|| format!("traversal benchmark on {name}"))?;
        let ratio = median(&b.paired_ratios);
        let (lowest, highest) = range(&b.paired_ratios);
        writeln!(
            md,
            "| {name} | {} | {} | {} | {:.3} | {:.3} | {:.2} | {:.2}, {:.2} | {:.3} | {:.3} | {:.2} | {:.3} | {:.2} | {:.2} | {:.1}% | {:.2}% | {:.2}% |",
            b.triangles,
            b.instances,
            b.stack_entries,
            b.gpu_rays_per_second / 1e6,
            b.cpu_rays_per_second / 1e6,
            ratio,
            lowest,
            highest,
            b.gpu_sorted_rays_per_second / 1e6,
            b.cpu_sorted_rays_per_second / 1e6,
            b.gpu_sorted_rays_per_second / b.gpu_rays_per_second,
            b.gpu_bvh2_rays_per_second / 1e6,
            b.gpu_bvh2_rays_per_second / b.gpu_rays_per_second,
            b.cpu_bvh2_rays_per_second / b.cpu_rays_per_second,
            100.0 * b.hit_fraction,
            100.0 * b.agreement,
            100.0 * b.bvh2_agreement
        )?;
        traversal_rows.push(TraversalRow {
            scene: name.clone(),
            triangles: b.triangles,
            wgsl_mrays_per_s: b.gpu_rays_per_second / 1e6,
            cpu_mrays_per_s: b.cpu_rays_per_second / 1e6,
            traversal_ratio_vs_obvhs: ratio,
            paired_ratios: b.paired_ratios.clone(),
            wgsl_sorted_mrays_per_s: b.gpu_sorted_rays_per_second / 1e6,
            cpu_sorted_mrays_per_s: b.cpu_sorted_rays_per_second / 1e6,
            wgsl_sorted_speedup: b.gpu_sorted_rays_per_second / b.gpu_rays_per_second,
            wgsl_bvh2_mrays_per_s: b.gpu_bvh2_rays_per_second / 1e6,
            bvh2_vs_cwbvh: b.gpu_bvh2_rays_per_second / b.gpu_rays_per_second,
            cpu_bvh2_mrays_per_s: b.cpu_bvh2_rays_per_second / 1e6,
            cpu_bvh2_vs_cwbvh: b.cpu_bvh2_rays_per_second / b.cpu_rays_per_second,
            bvh2_agreement: b.bvh2_agreement,
        });
    }

    log("reference path tracing");
    let reference = reference_paths(&gpu, opts.reference_spp)?;
    writeln!(
        md,
        "\n## Reference path tracing (Lambertian Cornell box {0}x{0}, {1} spp, unlimited depth, Russian roulette from depth {2})\n",
        REFERENCE_SIZE, opts.reference_spp, REFERENCE_INTEGRATOR.rr_depth
    )?;
    writeln!(
        md,
        "| renderer | M paths/s (median of {REFERENCE_ROUNDS} rounds) | mean radiance (RGB) | ratio to Mitsuba (median of {REFERENCE_ROUNDS} paired rounds) |\n|---|---:|---|---:|"
    )?;
    let mean = |m: [f64; 3]| format!("{:.4} {:.4} {:.4}", m[0], m[1], m[2]);
    // The median of the paired rounds' ratios (not a ratio of medians).
    let mitsuba_ratio =
        (!reference.paired_ratios.is_empty()).then(|| median(&reference.paired_ratios));
    writeln!(
        md,
        "| flicker WGSL ({}) | {:.3} | {} | {} |",
        gpu.summary,
        reference.paths_per_s / 1e6,
        mean(reference.mean_rgb),
        mitsuba_ratio.map_or("n/a".into(), |r| format!("{r:.2}"))
    )?;
    writeln!(
        md,
        "| flicker WGSL, wavefront (extend, shade, shadow kernels) | {:.3} | largest pixel difference from the megakernel: {:.3e} | {} |",
        reference.wavefront_paths_per_s / 1e6,
        reference.wavefront_max_difference,
        reference.mitsuba.as_ref().map_or("n/a".into(), |m| format!(
            "{:.2}",
            reference.wavefront_paths_per_s / m.paths_per_second()
        ))
    )?;
    // The Mitsuba row belongs to the table above, so the kernel times follow it.
    match &reference.mitsuba {
        Some(m) => writeln!(
            md,
            "| Mitsuba {} scalar_rgb ({} threads) | {:.3} | {} | 1.00 |",
            m.version,
            m.threads,
            m.paths_per_second() / 1e6,
            mean(m.mean_rgb)
        )?,
        None => writeln!(
            md,
            "\nMitsuba 3 not measured: {}",
            reference.mitsuba_missing.as_deref().unwrap_or("?")
        )?,
    }
    if !reference.paired_ratios.is_empty() {
        let (lowest, highest) = range(&reference.paired_ratios);
        writeln!(
            md,
            "\nThe megakernel over Mitsuba in each round (ours timed, then Mitsuba's, alternating): {}; lowest {:.2}, highest {:.2}. The wavefront is timed once, against Mitsuba's median round.",
            reference
                .paired_ratios
                .iter()
                .map(|r| format!("{r:.2}"))
                .collect::<Vec<_>>()
                .join(", "),
            lowest,
            highest,
        )?;
    }
    writeln!(
        md,
        "\nThe wavefront's kernels, each submitted and waited for alone, against the megakernel's {:.3} s for the whole reference: {}\n",
        reference.seconds,
        reference
            .wavefront_kernel_seconds
            .iter()
            .map(|(k, s)| format!("{k} {s:.3} s"))
            .collect::<Vec<_>>()
            .join(", ")
    )?;

    writeln!(
        md,
        "\n## Path tracer frame time ({} frames after one warm-up, 1 spp, max depth 8)\n",
        opts.frames
    )?;
    writeln!(
        md,
        "| scene | resolution | pass | GPU ms (mean) | CPU ms per frame incl. readback (mean) |"
    )?;
    writeln!(md, "|---|---|---|---:|---:|")?;
    for name in &opts.frame_scenes {
        for &(w, h) in &opts.resolutions {
            log(&format!("frame time: {name} {w}x{h}"));
            let scene = builtin_scene(name, (w, h))?;
            let settings =
                PathTracerSettings { width: w, height: h, max_depth: 8, rr_start_depth: 3 };
            let mut gpu_scene = SceneGpu::new(&gpu, &scene, settings)?;
            let mut tracer = PathTracer::new(&gpu, &gpu_scene)?;
            gpu_scene.update(&gpu, &scene);
            tracer.render(&gpu, &gpu_scene, 1, 1, 0)?;
            let mut gpu_ms: Vec<(String, f64, u32)> = Vec::new();
            let mut rays = 0u64;
            let start = Instant::now();
            for f in 0..opts.frames {
                let out = tracer.render(&gpu, &gpu_scene, 1, 1, f + 1)?;
                rays += out.rays;
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
                let g = if *n > 0 {
                    format!(
                        "{:.2}{}",
                        sum / *n as f64,
                        if gpu.has_timestamps() { "" } else { " (wall)" }
                    )
                } else {
                    "n/a".into()
                };
                writeln!(md, "| {name} | {w}x{h} | {pass} | {g} | {cpu_ms:.2} |")?;
            }
            let mean_ms: std::collections::BTreeMap<String, f64> =
                gpu_ms.iter().map(|(p, sum, n)| (p.clone(), sum / (*n).max(1) as f64)).collect();
            let frame_ms: f64 = mean_ms.values().sum();
            let rays_per_frame = rays as f64 / opts.frames as f64;
            frame_rows.push(FrameRow {
                scene: name.clone(),
                width: w,
                height: h,
                gpu_ms: mean_ms,
                rays_per_frame,
                frame_mrays_per_s: rays_per_frame / frame_ms / 1e3,
            });
        }
    }
    // Traversal's share of a frame, to first order: the frame's rays at the traversal-only rate
    // of the same scene (random rays, like the bounces' rays) against the frame's time.
    writeln!(
        md,
        "\n| scene | resolution | rays per frame | Mrays/s within the frame | traversal-only Mrays/s | frame rate / traversal-only rate |"
    )?;
    writeln!(md, "|---|---|---:|---:|---:|---:|")?;
    for f in &frame_rows {
        let alone = traversal_rows.iter().find(|t| t.scene == f.scene).map(|t| t.wgsl_mrays_per_s);
        let rate = f.frame_mrays_per_s;
        writeln!(
            md,
            "| {} | {}x{} | {:.0} | {rate:.3} | {} | {} |",
            f.scene,
            f.width,
            f.height,
            f.rays_per_frame,
            alone.map_or("n/a".into(), |a| format!("{a:.3}")),
            alone.map_or("n/a".into(), |a| format!("{:.2}", rate / a))
        )?;
    }
    log("device memory per method");
    let scratch = std::env::temp_dir().join(format!("flicker-bench-memory-{}", std::process::id()));
    let (memory_md, memory_rows) = crate::memory_table::table(&opts.resolutions, &scratch)?;
    write!(md, "\n{memory_md}")?;
    let json = serde_json::json!({
        "adapter": gpu.summary,
        "cpu_threads": rayon_threads(),
        "traversal_ratio_vs_obvhs": traversal_rows.iter().map(|t| (t.scene.clone(), serde_json::json!(t.traversal_ratio_vs_obvhs))).collect::<serde_json::Map<_, _>>(),
        "bvh2_vs_cwbvh": traversal_rows.iter().map(|t| (t.scene.clone(), serde_json::json!(t.bvh2_vs_cwbvh))).collect::<serde_json::Map<_, _>>(),
        "traversal": traversal_rows,
        "reference_paths_per_s": reference.paths_per_s,
        "reference_spp": opts.reference_spp,
        "reference_wavefront_paths_per_s": reference.wavefront_paths_per_s,
        "reference_wavefront_max_difference": reference.wavefront_max_difference,
        "reference_seconds": reference.seconds,
        "reference_wavefront_kernel_seconds": reference.wavefront_kernel_seconds.iter().map(|(k, s)| (k.clone(), serde_json::json!(s))).collect::<serde_json::Map<_, _>>(),
        "reference_mean_rgb": reference.mean_rgb,
        "mitsuba_paths_per_s": reference.mitsuba.as_ref().map(|m| m.paths_per_second()),
        "mitsuba_threads": reference.mitsuba.as_ref().map(|m| m.threads),
        "mitsuba_mean_rgb": reference.mitsuba.as_ref().map(|m| m.mean_rgb),
        "reference_paths_ratio_vs_mitsuba": mitsuba_ratio,
        "reference_paired_ratios_vs_mitsuba": reference.paired_ratios,
        "frames": frame_rows,
        "memory": memory_rows,
    });
    Ok(BenchReport { markdown: md, json })
}

const REFERENCE_SIZE: u32 = 64;
/// "Unlimited" depth on our side is a bound no Cornell-box path reaches under roulette (a path
/// survives 1000 white bounces with probability below 0.73^997).
const REFERENCE_INTEGRATOR: mitsuba::Integrator =
    mitsuba::Integrator { max_depth: None, rr_depth: 3 };
const REFERENCE_MAX_DEPTH: u32 = 1000;
/// Paired rounds of the reference against Mitsuba (ours, then Mitsuba's, alternating): one timing
/// each moved by a third between runs on an idle 2-core machine, so the ratio is the median of
/// the rounds' ratios and their range its spread, as the traversal's.
pub const REFERENCE_ROUNDS: usize = 3;

struct ReferenceBench {
    /// The megakernel's paths/s, the median of the rounds.
    paths_per_s: f64,
    /// The megakernel's time for the whole reference (the median round).
    seconds: f64,
    /// Each round's paths/s over Mitsuba's in the same round (empty without Mitsuba).
    paired_ratios: Vec<f64>,
    /// Each wavefront kernel's wall time when submitted alone, in crate::wavefront::Kernel order.
    wavefront_kernel_seconds: Vec<(String, f64)>,
    /// The same reference traced as a wavefront (crate::wavefront), and the largest difference
    /// of any pixel's channel from the megakernel's image.
    wavefront_paths_per_s: f64,
    wavefront_max_difference: f32,
    mean_rgb: [f64; 3],
    /// Mitsuba's median round (by paths/s).
    mitsuba: Option<mitsuba::MitsubaRun>,
    mitsuba_missing: Option<String>,
}

/// Paths per second of a converging reference (the Cornell box at 64x64, unlimited depth with
/// Russian roulette), and the same scene exported to Mitsuba 3 and rendered by its scalar CPU
/// path tracer in this run, when Python has Mitsuba, in [`REFERENCE_ROUNDS`] paired rounds.
fn reference_paths(gpu: &Gpu, spp: u32) -> Result<ReferenceBench> {
    let size = REFERENCE_SIZE;
    let scene = lambertian_cornell_box((size, size))?;
    let settings = PathTracerSettings {
        width: size,
        height: size,
        max_depth: REFERENCE_MAX_DEPTH,
        rr_start_depth: REFERENCE_INTEGRATOR.rr_depth,
    };
    let mut gpu_scene = SceneGpu::new(gpu, &scene, settings)?;
    let mut tracer = PathTracer::new(gpu, &gpu_scene)?;
    gpu_scene.update(gpu, &scene);
    tracer.render_reference(gpu, &gpu_scene, 1, 1, 0, &mut |_, _| {})?;
    let paths = (size * size) as f64 * spp as f64;
    let dir = std::env::temp_dir().join(format!("flicker_bench_mitsuba_{}", std::process::id()));
    // The Python with Mitsuba and the scene exported for it, once for every round.
    let mitsuba_job = match mitsuba::python() {
        Some(python) => {
            Some((python, mitsuba::write_scene(&scene, (size, size), &REFERENCE_INTEGRATOR, &dir)?))
        }
        None => None,
    };
    let mitsuba_missing = mitsuba_job.is_none().then(|| "no Python with the mitsuba package (pip install mitsuba; FLICKER_PYTHON picks the interpreter)".to_string());
    let mut seconds_per_round = Vec::with_capacity(REFERENCE_ROUNDS);
    let mut mitsuba_runs = Vec::with_capacity(REFERENCE_ROUNDS);
    let mut image = Vec::new();
    for _ in 0..REFERENCE_ROUNDS {
        let start = Instant::now();
        image = tracer.render_reference(gpu, &gpu_scene, spp, 1, 0, &mut |_, _| {})?;
        seconds_per_round.push(start.elapsed().as_secs_f64());
        if let Some((python, xml)) = &mitsuba_job {
            mitsuba_runs.push(mitsuba::render(python, xml, spp, &dir.join("mitsuba.exr"))?);
        }
    }
    let _ = std::fs::remove_dir_all(&dir);
    let seconds = median(&seconds_per_round);
    let paths_per_s = paths / seconds;
    let paired_ratios: Vec<f64> = seconds_per_round
        .iter()
        .zip(&mitsuba_runs)
        .map(|(s, m)| paths / s / m.paths_per_second())
        .collect();
    mitsuba_runs.sort_by(|a, b| a.paths_per_second().total_cmp(&b.paths_per_second()));
    let mitsuba = mitsuba_runs.get(mitsuba_runs.len() / 2).cloned();
    let wavefront = Wavefront::new(gpu, &gpu_scene)?;
    wavefront.render_reference(gpu, &gpu_scene, &tracer, 1, 1, 0)?;
    let start = Instant::now();
    let wf_image = wavefront.render_reference(gpu, &gpu_scene, &tracer, spp, 1, 0)?;
    let wavefront_paths_per_s = (size * size) as f64 * spp as f64 / start.elapsed().as_secs_f64();
    // Where its time goes: each kernel waited for alone (slower than the timed run above).
    let mut kernel_times = KernelTimes::default();
    wavefront.render_reference_per_kernel(
        gpu,
        &gpu_scene,
        &tracer,
        spp,
        1,
        0,
        &mut kernel_times,
    )?;
    let wavefront_kernel_seconds: Vec<(String, f64)> = Kernel::ALL
        .iter()
        .map(|k| (k.name().to_string(), kernel_times.seconds[*k as usize]))
        .collect();
    let wavefront_max_difference = image
        .iter()
        .zip(&wf_image)
        .flat_map(|(a, b)| (0..3).map(move |c| (a[c] - b[c]).abs()))
        .fold(0.0f32, f32::max);
    let n = image.len() as f64;
    let mean_rgb = [0, 1, 2].map(|c| image.iter().map(|p| p[c] as f64).sum::<f64>() / n);
    Ok(ReferenceBench {
        paths_per_s,
        seconds,
        paired_ratios,
        wavefront_kernel_seconds,
        wavefront_paths_per_s,
        wavefront_max_difference,
        mean_rgb,
        mitsuba,
        mitsuba_missing,
    })
}

/// A GPU fresh from idle runs at a fraction of its clock for a while (an H200 started at 345 of
/// 1980 MHz and made the first path-tracer frames 5x slower): render untimed frames for a second,
/// so that every timed section starts at working clocks.
fn warm_up(gpu: &Gpu) -> Result<()> {
    let scene = builtin_scene("cornell_box", (320, 180))?;
    let mut gpu_scene = SceneGpu::new(
        gpu,
        &scene,
        PathTracerSettings { width: 320, height: 180, max_depth: 8, rr_start_depth: 3 },
    )?;
    let mut tracer = PathTracer::new(gpu, &gpu_scene)?;
    gpu_scene.update(gpu, &scene);
    let start = Instant::now();
    let mut frame = 0;
    while frame < 2 || start.elapsed().as_secs_f64() < 1.0 {
        tracer.render(gpu, &gpu_scene, 1, 1, frame)?;
        frame += 1;
    }
    Ok(())
}

fn rayon_threads() -> usize {
    std::thread::available_parallelism().map(|n| n.get()).unwrap_or(1)
}
