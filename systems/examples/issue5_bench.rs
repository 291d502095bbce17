//! Per-pass GPU time of TAA and the hash cache (both lookups) next to 1 spp path tracing on the
//! courtyard, camera moving: `cargo run --release -p systems --example issue5_bench [W H FRAMES]`.
//! Prints a Markdown table of the median over the timed frames (after 3 untimed ones).

use anyhow::Result;
use render::gpu::Gpu;
use render::hash_cache::{HashCache, HashCacheLookup, HashCacheSettings};
use render::path_tracer::{PathTracer, PathTracerSettings};
use render::taa::{Taa, TaaSettings};
use std::collections::BTreeMap;

fn median(mut v: Vec<f64>) -> f64 {
    v.sort_by(f64::total_cmp);
    v[v.len() / 2]
}

fn main() -> Result<()> {
    let args: Vec<u32> = std::env::args().skip(1).map(|a| a.parse()).collect::<Result<_, _>>()?;
    let (w, h, frames) = match args[..] {
        [w, h, f] => (w, h, f),
        [] => (320, 180, 8),
        _ => anyhow::bail!("usage: issue5_bench [WIDTH HEIGHT FRAMES]"),
    };
    let gpu = Gpu::new()?;
    let mut scene = systems::bench::builtin_scene("courtyard", (w, h))?;
    let mut tracer = PathTracer::new(&gpu, &scene, PathTracerSettings { width: w, height: h, max_depth: 4, rr_start_depth: 3 })?;
    let mut taa = Taa::new(&gpu, &tracer, TaaSettings::default())?;
    let mut secondary = HashCache::new(&gpu, &tracer, HashCacheSettings::default())?;
    let mut first = HashCache::new(&gpu, &tracer, HashCacheSettings { lookup: HashCacheLookup::FirstHit, ..Default::default() })?;
    let mut times: BTreeMap<(String, String), Vec<f64>> = BTreeMap::new();
    let mut stats = vec![];
    let start = scene.camera.position;
    for f in 0..frames + 3 {
        scene.camera.position = start + glam::Vec3::new(0.05 * f as f32, 0.0, -0.05 * f as f32);
        tracer.update(&gpu, &scene);
        let mut record = |method: &str, timings: &[render::timing::PassTiming]| {
            if f >= 3 {
                for t in timings {
                    times.entry((method.to_string(), t.pass.clone())).or_default().push(t.gpu_ms.unwrap_or(t.cpu_ms));
                }
            }
        };
        let pt = tracer.render(&gpu, 1, 1, f)?;
        record("pt_1spp", &pt.timings);
        let out = taa.render(&gpu, &tracer, 1, f)?;
        record("taa", &out.timings);
        let out = secondary.render(&gpu, &tracer, &scene.camera, 1, f, None)?;
        record("hash_cache (secondary hit)", &out.timings);
        stats.push(("secondary", out.stats));
        let out = first.render(&gpu, &tracer, &scene.camera, 1, f, None)?;
        record("hash_cache (first hit)", &out.timings);
        stats.push(("first", out.stats));
    }
    println!("Adapter: {}; {w}x{h}, courtyard, max depth 4, median of {frames} frames (GPU timestamps where available)\n", gpu.summary);
    println!("| method | pass | ms |\n|---|---|---|");
    for ((m, p), v) in times {
        println!("| {m} | {p} | {:.2} |", median(v));
    }
    if let Some((_, s)) = stats.iter().rev().find(|(k, _)| *k == "secondary") {
        println!("\nsecondary-hit cache, last frame: occupancy {:.4}, evicted {}, inserted {}, update paths {}", s.occupancy(), s.evicted, s.inserted, s.update_paths);
    }
    if let Some((_, s)) = stats.iter().rev().find(|(k, _)| *k == "first") {
        println!("first-hit cache, last frame: occupancy {:.4}, evicted {}, inserted {}, update paths {}", s.occupancy(), s.evicted, s.inserted, s.update_paths);
    }
    Ok(())
}
