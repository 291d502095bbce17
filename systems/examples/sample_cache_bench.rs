//! Per-pass GPU time of the stable sample cache (reserve = reprojection, trace, shade,
//! reconstruct) for the single / multi / adaptive retrace strategies on the moving hairball
//! camera, next to the paper's figure 7 (RTX 3060, 1080p).
//!
//! cargo run --release -p systems --example sample_cache_bench -- [WIDTH HEIGHT FRAMES]

use std::path::Path;

use render::gpu::Gpu;
use render::path_tracer::{PathTracer, PathTracerSettings};
use render::sample_cache::{PASSES, Retrace, SampleCache, SampleCacheSettings};
use sim::{Scenario, Simulation};

fn main() -> anyhow::Result<()> {
    let args: Vec<u32> = std::env::args().skip(1).map(|a| a.parse()).collect::<Result<_, _>>()?;
    let (w, h, frames) = match args.as_slice() {
        [w, h, f] => (*w, *h, *f),
        [] => (320, 180, 12),
        _ => anyhow::bail!("usage: sample_cache_bench [WIDTH HEIGHT FRAMES]"),
    };
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("../scenarios/hairball_camera.ron");
    let mut scenario = Scenario::load(&path)?;
    scenario.resolution = (w, h);
    let gpu = Gpu::new()?;
    println!("adapter: {}; {w}x{h}, {frames} frames (first 2 skipped: the cache fills)", gpu.summary.name);
    println!("{:<10} {:>10} {:>10} {:>10} {:>12} {:>10} {:>12}", "retrace", "reserve", "trace", "shade", "reconstruct", "total", "rays/frame");
    let mut totals = vec![];
    for retrace in [Retrace::Single, Retrace::Multi, Retrace::Adaptive] {
        let mut sim = Simulation::new(&scenario)?;
        let settings = PathTracerSettings { width: w, height: h, max_depth: scenario.max_depth, rr_start_depth: 3 };
        let mut tracer = PathTracer::new(&gpu, sim.scene(), settings)?;
        let mut cache = SampleCache::new(&gpu, &tracer, SampleCacheSettings { retrace, ..Default::default() })?;
        let mut sums = vec![0.0f64; PASSES.len()];
        let mut rays = 0u64;
        let mut counted = 0;
        for f in 0..frames {
            tracer.update(&gpu, sim.scene());
            let out = cache.render(&gpu, &tracer, scenario.seed, sim.frame())?;
            if f >= 2 {
                for (i, t) in out.timings.iter().enumerate() {
                    sums[i] += t.gpu_ms.unwrap_or(f64::NAN);
                }
                rays += out.stats.rays as u64;
                counted += 1;
            }
            sim.step();
        }
        let mean: Vec<f64> = sums.iter().map(|s| s / counted as f64).collect();
        let total: f64 = mean.iter().sum();
        // The paper's figure 7 skips shading: compare reserve + trace + reconstruct.
        totals.push(mean[0] + mean[1] + mean[3]);
        println!(
            "{:<10} {:>10.2} {:>10.2} {:>10.2} {:>12.2} {:>10.2} {:>12}",
            format!("{retrace:?}"),
            mean[0],
            mean[1],
            mean[2],
            mean[3],
            total,
            rays / counted as u64
        );
    }
    println!(
        "without shading (reserve + trace + reconstruct): single {:.2}, multi {:.2}, adaptive {:.2} ms; adaptive / multi = {:.2} (paper, RTX 3060 1080p: 5.79 / 10.37 = 0.56, single 5.06)",
        totals[0],
        totals[1],
        totals[2],
        totals[2] / totals[1]
    );
    Ok(())
}
