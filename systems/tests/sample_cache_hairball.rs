//! Issue 5 relations on a moving hairball camera (scenarios/hairball_camera.ron at 64x36): the
//! stable sample cache flickers less than 1 spp path tracing and than 1 spp + TAA at the same
//! shading budget (one path per pixel per frame), adaptive retracing traces clearly fewer rays
//! than multi, and it leaves less stale visibility (ghosting) than single. Relations, not numbers.
//! Every method runs on the same tracer, resolution, seed and frames, and its flicker is the
//! reprojected SMAPE against its own previous frame through its own motion vectors.

use std::path::Path;

use metrics::Image;
use render::gpu::Gpu;
use render::path_tracer::{PathTracer, PathTracerSettings};
use render::scene_gpu::SceneGpu;
use sample_cache::{Retrace, SampleCache, SampleCacheSettings};
use sim::{Scenario, Simulation};
use taa::{Taa, TaaSettings};

fn image(w: u32, h: u32, rgba: &[[f32; 4]]) -> Image {
    Image::new(w, h, rgba.iter().map(|p| [p[0], p[1], p[2]]).collect())
}

#[test]
fn sample_cache_on_a_moving_hairball_camera() {
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("../scenarios/hairball_camera.ron");
    let mut scenario = Scenario::load(&path).expect("hairball_camera.ron");
    let (w, h) = (64, 36);
    let frames = 10;
    scenario.resolution = (w, h);
    let gpu = Gpu::new().expect("a wgpu adapter");
    let mut sim = Simulation::new(&scenario).expect("simulation");
    let settings = PathTracerSettings {
        width: w,
        height: h,
        max_depth: scenario.max_depth,
        rr_start_depth: 3,
    };
    let mut sg = SceneGpu::new(&gpu, sim.scene(), settings).expect("scene");
    let mut tracer = PathTracer::new(&gpu, &sg).expect("path tracer");
    let variants = [Retrace::Single, Retrace::Multi, Retrace::Adaptive];
    let mut caches: Vec<SampleCache> = variants
        .iter()
        .map(|&retrace| {
            SampleCache::new(&gpu, &sg, SampleCacheSettings { retrace, ..Default::default() })
                .expect("sample cache")
        })
        .collect();
    let mut taa = Taa::new(&gpu, &sg, TaaSettings::default()).expect("taa");
    // Per method (pt_1spp, single, multi, adaptive, taa): previous frame and SMAPE sum; per cache
    // (single, multi, adaptive): rays traced and stale visible samples.
    let mut previous: Vec<Option<Image>> = vec![None; 5];
    let mut smape = [0.0f64; 5];
    let mut shaded = [0u64; 5];
    let mut rays = [0u64; 3];
    let mut stale = [0u64; 3];
    let eps = scenario.smape_epsilon;
    for f in 0..frames {
        sg.update(&gpu, sim.scene());
        let frame = sim.frame();
        let pt = tracer.render(&gpu, &sg, 1, scenario.seed, frame).expect("pt frame");
        let mut outputs = vec![(pt.radiance, pt.gbuffer.motion)];
        for (i, cache) in caches.iter_mut().enumerate() {
            let out = cache.render(&gpu, &sg, scenario.seed, frame).expect("cache frame");
            // From frame 2 on: the caches have filled.
            if f >= 2 {
                rays[i] += out.stats.rays as u64;
                stale[i] += cache.audit(&gpu, &sg).expect("audit") as u64;
            }
            outputs.push((out.radiance, out.motion));
            if f >= 2 {
                shaded[i + 1] += out.stats.shaded as u64;
            }
        }
        let t = taa.render(&gpu, &sg, scenario.seed, frame).expect("taa frame");
        if f >= 2 {
            shaded[0] += pt.shaded;
            shaded[4] += t.shaded;
        }
        outputs.push((t.radiance, t.motion));
        for (m, (radiance, motion)) in outputs.into_iter().enumerate() {
            let img = image(w, h, &radiance);
            if f >= 3 {
                let prev = previous[m].as_ref().expect("previous frame");
                smape[m] += metrics::smape_reprojected(&img, prev, &motion, eps).mean;
            }
            previous[m] = Some(img);
        }
        sim.step();
    }
    eprintln!(
        "SMAPE sums (pt_1spp, single, multi, adaptive, taa): {smape:?}; shaded paths: {shaded:?}; rays (single, multi, adaptive): {rays:?}; stale visible: {stale:?}"
    );
    // Equal shading budget: the uniform-shading caches shade one path per pixel, like 1 spp and TAA.
    assert!(shaded.iter().all(|&s| s == shaded[0]), "shading budgets differ: {shaded:?}");
    assert!(smape[3] < smape[0], "adaptive cache flickers more than 1 spp: {smape:?}");
    for (i, name) in ["single", "multi", "adaptive"].iter().enumerate() {
        assert!(smape[i + 1] < smape[4], "{name} cache flickers more than 1 spp + TAA: {smape:?}");
    }
    assert!(
        rays[2] as f64 <= 0.6 * rays[1] as f64,
        "adaptive traces {} rays vs multi {}",
        rays[2],
        rays[1]
    );
    assert!(
        stale[2] < stale[0],
        "adaptive leaves {} stale visible samples vs single {}",
        stale[2],
        stale[0]
    );
    // Multi retraces every sample every frame, so none can be stale after its trace pass.
    assert_eq!(
        stale[1], 0,
        "multi retraces everything, yet leaves {} stale visible samples",
        stale[1]
    );
}

#[test]
fn hairball_camera_scenario_plays_end_to_end() {
    use systems::playback::{Overrides, RunOptions, run};
    let scenario = Path::new(env!("CARGO_MANIFEST_DIR")).join("../scenarios/hairball_camera.ron");
    let out = std::env::temp_dir().join(format!("flicker-ssc-{}", std::process::id()));
    let summary = run(&RunOptions {
        scenario,
        overrides: Overrides {
            frames: Some(3),
            resolution: Some((32, 18)),
            out: Some(out.clone()),
            ..Default::default()
        },
        cache_dir: Some(out.join("cache")),
        progress: false,
    })
    .expect("run");
    let labels: std::collections::BTreeSet<String> =
        summary.records.iter().map(|r| r.method.clone()).collect();
    for label in [
        "pt_1spp",
        "pt_4spp",
        "ssc_single",
        "ssc_multi",
        "ssc_adaptive",
        "ssc_adaptive_taa",
        "hash_cache_taa",
    ] {
        assert!(labels.contains(label), "{label} missing from {labels:?}");
    }
    // Each method's effective temporal window is in the manifest (issue 15): TAA's exponential
    // blend (α 0.1: 19 frames), the cache's n_target · 19 shades at one per pixel and frame, and
    // TAA over the cache longer than either.
    let manifest: serde_json::Value = serde_json::from_str(
        &std::fs::read_to_string(out.join("manifest.json")).expect("manifest.json"),
    )
    .expect("manifest JSON");
    let window = |label: &str| {
        let methods = manifest["settings"]["methods"].as_array().expect("settings.methods");
        methods
            .iter()
            .find(|m| m["label"] == label)
            .and_then(|m| m["temporal_window"].as_f64())
            .unwrap_or_else(|| panic!("{label}: no temporal window"))
    };
    // (α is an f32: 19 up to its rounding.)
    for (label, expected) in [("pt_1spp", 1.0), ("taa", 19.0), ("ssc_adaptive", 76.0)] {
        assert!(
            (window(label) - expected).abs() < 1e-5 * expected,
            "{label}: {} frames, expected {expected}",
            window(label)
        );
    }
    assert!(
        window("ssc_adaptive_taa") > 76.0
            && window("hash_cache_taa") > window("hash_cache_secondary_hit")
    );
    // TAA over the cache: the resolve's pass follows the cache's four.
    let taa_rows: Vec<_> =
        summary.records.iter().filter(|r| r.method == "ssc_adaptive_taa").collect();
    assert!(
        taa_rows.iter().all(|r| r.passes.iter().any(|(p, _)| p == "taa_resolve")),
        "{:?}",
        taa_rows.first().map(|r| &r.passes)
    );
    let csv = std::fs::read_to_string(out.join("frames.csv")).expect("frames.csv");
    for column in ["shaded", "rays", "primary_rays", "occupancy", "gpu_ms_reserve"] {
        assert!(csv.lines().next().unwrap().contains(column), "{column} not in frames.csv");
    }
    // The cache's counters are per frame: the adaptive cache shades one sample per pixel.
    let shaded = summary
        .records
        .iter()
        .filter(|r| r.method == "ssc_adaptive")
        .map(|r| r.shaded.expect("shaded paths reported"))
        .collect::<Vec<_>>();
    assert_eq!(shaded, vec![32 * 18; 3]);
    // Every method reports its rays and shaded paths, and no pass carries a whole frame: the
    // path tracer books two passes, the caches four (reserve = reprojection only).
    for r in &summary.records {
        assert!(
            r.rays.is_some_and(|n| n > 0) && r.shaded.is_some(),
            "{}: rays {:?}, shaded {:?}",
            r.method,
            r.rays,
            r.shaded
        );
        assert!(r.passes.iter().all(|(_, ms)| ms.is_some()), "{}: {:?}", r.method, r.passes);
    }
    let _ = std::fs::remove_dir_all(&out);
}
