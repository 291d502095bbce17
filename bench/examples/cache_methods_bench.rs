//! The caches' speed, every method side by side in one run on the moving hairball camera
//! (scenarios/hairball_camera.ron): 1 spp path tracing, TAA, the hash cache (alone and under
//! TAA) and the stable sample cache with single / multi / adaptive retracing. Prints per-pass
//! times (GPU timestamps where the adapter has them, else per-pass wall time), rays and shaded
//! paths per frame, the sample cache's per-dispatch times, and the paper's figure-7 ratios.
//!
//! cargo run -j2 -p bench --example cache_methods_bench -- [WIDTH HEIGHT FRAMES]
//! (run it on an idle machine: on llvmpipe, concurrent load distorts the pass times)

use std::collections::BTreeMap;
use std::path::Path;

use hash_cache::{HashCache, HashCacheSettings};
use render::gpu::Gpu;
use render::path_tracer::{PathTracer, PathTracerSettings};
use render::scene_gpu::SceneGpu;
use render::timing::PassTiming;
use sample_cache::{DISPATCHES, Retrace, SampleCache, SampleCacheSettings};
use sim::{Scenario, Simulation};
use taa::{Taa, TaaSettings};

/// Frames rendered before timing starts (the caches fill, pipelines warm up).
const WARM_UP: u32 = 2;

#[derive(Default)]
struct Sums {
    passes: Vec<(String, f64)>,
    rays: u64,
    shaded: u64,
    frames: u32,
}

impl Sums {
    fn add(&mut self, timings: &[PassTiming], rays: u64, shaded: u64) {
        for t in timings {
            match self.passes.iter_mut().find(|(p, _)| *p == t.pass) {
                Some(e) => e.1 += t.ms,
                None => self.passes.push((t.pass.clone(), t.ms)),
            }
        }
        self.rays += rays;
        self.shaded += shaded;
        self.frames += 1;
    }

    fn mean(&self, pass: &str) -> f64 {
        self.passes.iter().find(|(p, _)| p == pass).map_or(0.0, |e| e.1 / self.frames as f64)
    }

    fn total(&self) -> f64 {
        self.passes.iter().map(|e| e.1).sum::<f64>() / self.frames as f64
    }
}

fn main() -> anyhow::Result<()> {
    let args: Vec<u32> = std::env::args().skip(1).map(|a| a.parse()).collect::<Result<_, _>>()?;
    let (w, h, frames) = match args.as_slice() {
        [w, h, f] => (*w, *h, *f),
        [] => (320, 180, 8),
        _ => anyhow::bail!("usage: cache_methods_bench [WIDTH HEIGHT FRAMES]"),
    };
    anyhow::ensure!(frames > WARM_UP, "FRAMES must exceed the {WARM_UP} warm-up frames");
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("../scenarios/hairball_camera.ron");
    let mut scenario = Scenario::load(&path)?;
    scenario.resolution = (w, h);
    let gpu = Gpu::new()?;
    let mut sim = Simulation::new(&scenario)?;
    let settings = PathTracerSettings {
        width: w,
        height: h,
        max_depth: scenario.max_depth,
        rr_start_depth: 3,
    };
    let mut sg = SceneGpu::new(&gpu, sim.scene(), settings)?;
    let mut tracer = PathTracer::new(&gpu, &sg)?;
    let mut taa = Taa::new(&gpu, &sg, TaaSettings::default())?;
    let mut hc = HashCache::new(&gpu, &sg, HashCacheSettings::default())?;
    let mut hc_taa = (
        HashCache::new(&gpu, &sg, HashCacheSettings::default())?,
        Taa::new(&gpu, &sg, TaaSettings::default())?,
    );
    let strategies = [Retrace::Single, Retrace::Multi, Retrace::Adaptive];
    let mut caches: Vec<SampleCache> = strategies
        .iter()
        .map(|&retrace| {
            SampleCache::new(&gpu, &sg, SampleCacheSettings { retrace, ..Default::default() })
        })
        .collect::<Result<_, _>>()?;
    let labels = [
        "pt_1spp",
        "taa",
        "hash_cache",
        "hash_cache_taa",
        "ssc_single",
        "ssc_multi",
        "ssc_adaptive",
    ];
    let mut sums: BTreeMap<&str, Sums> = BTreeMap::new();
    let mut dispatch: Vec<Vec<f64>> = vec![vec![0.0; DISPATCHES.len()]; strategies.len()];
    let mut primary_rays = [0u64; 3];
    let mut clock = None;
    for f in 0..frames {
        sg.update(&gpu, sim.scene());
        let frame = sim.frame();
        let timed = f >= WARM_UP;
        let mut record = |label: &'static str, timings: &[PassTiming], rays: u64, shaded: u64| {
            if timed {
                clock = clock.or(timings.first().map(|t| t.clock));
                sums.entry(label).or_default().add(timings, rays, shaded);
            }
        };
        let pt = tracer.render(&gpu, &sg, 1, scenario.seed, frame)?;
        record("pt_1spp", &pt.timings, pt.rays, pt.shaded);
        let t = taa.render(&gpu, &sg, scenario.seed, frame)?;
        record("taa", &t.timings, t.rays, t.shaded);
        let o = hc.render(&gpu, &sg, &sim.scene().camera, scenario.seed, frame, None)?;
        record("hash_cache", &o.timings, o.rays, o.shaded);
        let o = hc_taa.0.render(
            &gpu,
            &sg,
            &sim.scene().camera,
            scenario.seed,
            frame,
            Some(&mut hc_taa.1),
        )?;
        record("hash_cache_taa", &o.timings, o.rays, o.shaded);
        for (i, cache) in caches.iter_mut().enumerate() {
            let o = cache.render(&gpu, &sg, scenario.seed, frame)?;
            record(labels[4 + i], &o.timings, o.stats.all_rays as u64, o.stats.shaded as u64);
            if timed {
                for (d, t) in o.dispatch_timings.iter().enumerate() {
                    dispatch[i][d] += t.ms;
                }
                primary_rays[i] += o.stats.rays as u64;
            }
        }
        sim.step();
        // Per frame, to tell a steady cost from outliers in the means.
        let ms = |timings: &[PassTiming], pass: &str| {
            timings.iter().find(|t| t.pass == pass).map_or(0.0, |t| t.ms)
        };
        eprintln!(
            "frame {f}: pt path_trace {:.0} ms, taa_trace {:.0} ms",
            ms(&pt.timings, "path_trace"),
            ms(&t.timings, "taa_trace")
        );
    }
    let n = (frames - WARM_UP) as f64;
    let clock = clock.map_or("?", |c| c.name());
    println!(
        "adapter: {}; hairball_camera.ron at {w}x{h}, max depth {}, mean of frames {WARM_UP}..{frames}; clock: {clock}\n",
        gpu.summary, scenario.max_depth
    );
    println!(
        "| method | pass ms ({clock}) | total ms | rays / frame | shaded paths / frame |\n|---|---|---:|---:|---:|"
    );
    for label in labels {
        let s = &sums[label];
        let passes: Vec<String> =
            s.passes.iter().map(|(p, ms)| format!("{p} {:.1}", ms / n)).collect();
        println!(
            "| {label} | {} | {:.1} | {} | {} |",
            passes.join(", "),
            s.total(),
            s.rays / s.frames as u64,
            s.shaded / s.frames as u64
        );
    }
    println!(
        "\nsample cache per dispatch (ms, {clock}):\n\n| dispatch | single | multi | adaptive |\n|---|---:|---:|---:|"
    );
    for (d, name) in DISPATCHES.iter().enumerate() {
        println!(
            "| {name} | {:.1} | {:.1} | {:.1} |",
            dispatch[0][d] / n,
            dispatch[1][d] / n,
            dispatch[2][d] / n
        );
    }
    println!(
        "| primary rays / frame | {} | {} | {} |",
        primary_rays[0] / n as u64,
        primary_rays[1] / n as u64,
        primary_rays[2] / n as u64
    );
    // The paper's figure 7 times reprojection and retracing without shading.
    let no_shade = |label: &str| {
        let s = &sums[label];
        s.mean("reserve") + s.mean("trace") + s.mean("reconstruct")
    };
    let (single, multi, adaptive) =
        (no_shade("ssc_single"), no_shade("ssc_multi"), no_shade("ssc_adaptive"));
    println!(
        "\nreprojection (1-pass, `reserve`): {:.1} ms; without shading: single {single:.1}, multi {multi:.1}, adaptive {adaptive:.1} ms; \
         adaptive / multi = {:.2}, single / multi = {:.2} (paper, RTX 3060 1080p: 5.79 / 10.37 = 0.56, 5.06 / 10.37 = 0.49)",
        sums["ssc_adaptive"].mean("reserve"),
        adaptive / multi,
        single / multi
    );
    println!(
        "trace pass only: adaptive / multi = {:.2} (paper's tracing column: 1.46 / 7.15 = 0.20); reprojection adaptive / multi = {:.2} (paper: 2.47 / 1.49 = 1.66); \
         primary rays adaptive / multi = {:.2}",
        sums["ssc_adaptive"].mean("trace") / sums["ssc_multi"].mean("trace"),
        sums["ssc_adaptive"].mean("reserve") / sums["ssc_multi"].mean("reserve"),
        primary_rays[2] as f64 / primary_rays[1] as f64
    );
    println!(
        "1 spp path_trace pass / TAA taa_trace pass = {:.2} (both trace one path per pixel)",
        sums["pt_1spp"].mean("path_trace") / sums["taa"].mean("taa_trace")
    );
    Ok(())
}
