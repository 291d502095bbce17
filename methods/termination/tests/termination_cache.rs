//! The termination cache on the GPU (termination::TerminationCache): the furnace through
//! the cache, the two ends (path tracing, first vertex), path length against the rule, and the
//! record moments in a uniformly lit scene.

use render::path_tracer::{PathTracer, PathTracerSettings};
use render::scene::SceneDesc;
use render::scene_gpu::SceneGpu;
use termination::{
    Incomplete, RadianceScale, TerminationCache, TerminationOutput, TerminationRule,
    TerminationSettings,
};

use common::{H, W, furnace, gpu, room_scene};
use testkit::test_scenes as common;

fn scene_gpu(scene: &SceneDesc, max_depth: u32) -> SceneGpu {
    SceneGpu::new(
        gpu(),
        scene,
        PathTracerSettings { width: W, height: H, max_depth, rr_start_depth: max_depth + 1 },
    )
    .expect("scene")
}

/// The settings these tests were written for: K = 4 (fast on lavapipe) and absolute thresholds
/// in radiance unit 1 (the room's and the furnace's own scale). `paper_conditions` tests the
/// defaults (K = 32, the cache's mean as the unit).
fn settings(rule: TerminationRule) -> TerminationSettings {
    TerminationSettings {
        rule,
        capacity: 1 << 12,
        warmup_frames: 32,
        samples_per_vertex: 4,
        radiance_scale: RadianceScale::Stated,
        ..Default::default()
    }
}

/// `frames` frames of one rule (the first after the warm-up).
fn run(
    sg: &SceneGpu,
    scene: &SceneDesc,
    rule: TerminationRule,
    frames: u32,
) -> Vec<TerminationOutput> {
    let mut cache = TerminationCache::new(gpu(), sg, settings(rule)).expect("termination cache");
    (0..frames).map(|f| cache.render(gpu(), sg, &scene.camera, 5, f).expect("render")).collect()
}

fn image_mean(img: &[[f32; 4]]) -> f64 {
    img.iter().map(|c| (c[0] + c[1] + c[2]) as f64 / 3.0).sum::<f64>() / img.len() as f64
}

const VB_HUGE: TerminationRule = TerminationRule::VarianceBounding { t: 1e30, relative: false };
const VB_ZERO: TerminationRule = TerminationRule::VarianceBounding { t: 0.0, relative: false };

#[test]
fn furnace_radiance_through_the_cache_for_every_rule() {
    // Walls of albedo 0.5 emitting 0.5: L = 1 everywhere; the cache holds 0.5 (emission apart).
    let (scene, expected) = furnace();
    let sg = scene_gpu(&scene, 12);
    let rules = [
        TerminationRule::FirstVertex,
        TerminationRule::VarianceBounding { t: 0.01, relative: false },
        TerminationRule::MseMinimisation { s: 100.0, margin: 1.1, bias_clamp: 0.1 },
        TerminationRule::AreaSpread { c: 0.01 },
    ];
    for rule in rules {
        let out = run(&sg, &scene, rule, 2);
        let mean = image_mean(&out[1].radiance);
        eprintln!("{rule:?}: furnace image mean {mean}");
        // 12 bounces of path tracing lose 0.5^12 of L; the cache converges to the same within
        // its 32 warm-up propagations. 3 % covers 1 spp noise over 576 pixels.
        assert!(
            (mean - expected as f64).abs() < 0.03,
            "{rule:?}: image mean {mean}, expected {expected}"
        );
        // After the warm-up nearly every vertex finds a filled record (the others path trace).
        eprintln!("{rule:?}: {:?}", out[1].stats);
        assert!(
            out[1].stats.unknown * 20 <= W * H,
            "{rule:?}: {} vertices without a filled record",
            out[1].stats.unknown
        );
    }
    // Uniform lighting: the record's squared bias is noise around zero, small next to E[Y]².
    let mut cache =
        TerminationCache::new(gpu(), &sg, settings(TerminationRule::FirstVertex)).unwrap();
    cache.render(gpu(), &sg, &scene.camera, 5, 0).unwrap();
    let records: Vec<_> =
        cache.read_records(gpu()).unwrap().into_iter().filter(|r| r.vertices > 0.0).collect();
    assert!(records.len() > 20, "only {} filled records", records.len());
    let (mut bias, mut mean2) = (0.0, 0.0);
    for r in &records {
        let m = (r.mean[0] + r.mean[1] + r.mean[2]) as f64 / 3.0;
        bias += (r.marginal as f64 - m * m) / records.len() as f64;
        mean2 += m * m / records.len() as f64;
        assert!((m - 0.5).abs() < 0.1, "record mean {m}, expected 0.5");
    }
    assert!(bias.abs() < 0.05 * mean2, "mean squared bias {bias} vs E[Y]² {mean2}");
}

#[test]
fn the_ends_path_tracing_and_first_vertex() {
    let scene = room_scene();
    let sg = scene_gpu(&scene, 6);
    // t = ∞ never terminates: the same paths, bit for bit, as the path tracing rule (the cache's
    // lookups draw from their own random stream).
    let a = run(&sg, &scene, TerminationRule::PathTracing, 2);
    let b = run(&sg, &scene, VB_HUGE, 2);
    for f in 0..2 {
        assert_eq!(a[f].radiance, b[f].radiance, "frame {f}: t = 1e30 differs from path tracing");
        assert_eq!(a[f].path_length, b[f].path_length);
    }
    // ... and the path tracing rule is the lab's path tracer within noise: mean image over 8
    // frames against 8 spp of PathTracer, within 4 standard errors of the difference.
    let mut ours = vec![0.0f64; (W * H) as usize];
    let theirs = pt_mean_image(&sg, 8);
    let mut cache =
        TerminationCache::new(gpu(), &sg, settings(TerminationRule::PathTracing)).unwrap();
    let mut per_frame = Vec::new();
    for f in 0..8 {
        let out = cache.render(gpu(), &sg, &scene.camera, 5, 100 + f).unwrap();
        per_frame.push(image_mean(&out.radiance));
        for (o, c) in ours.iter_mut().zip(&out.radiance) {
            *o += (c[0] + c[1] + c[2]) as f64 / 3.0 / 8.0;
        }
    }
    let (m_ours, m_theirs) = (
        ours.iter().sum::<f64>() / ours.len() as f64,
        theirs.iter().sum::<f64>() / theirs.len() as f64,
    );
    let mean_pf = per_frame.iter().sum::<f64>() / 8.0;
    let se =
        (per_frame.iter().map(|v| (v - mean_pf) * (v - mean_pf)).sum::<f64>() / 7.0 / 8.0).sqrt();
    assert!(
        (m_ours - m_theirs).abs() < 4.0 * se * 2f64.sqrt() + 1e-6,
        "path tracing rule {m_ours} vs PathTracer {m_theirs} (se {se})"
    );
    // t = 0 terminates at the first vertex: the first-vertex image, path length 1 where a
    // record exists.
    let first = run(&sg, &scene, TerminationRule::FirstVertex, 2);
    let zero = run(&sg, &scene, VB_ZERO, 2);
    let same = first[1].radiance.iter().zip(&zero[1].radiance).filter(|(x, y)| x == y).count();
    assert!(
        same as f64 >= 0.99 * (W * H) as f64,
        "t = 0 equals first vertex at {same} of {} pixels",
        W * H
    );
    assert!(
        first[1].mean_path_length <= 1.0 + first[1].stats.unknown as f64 / (W * H) as f64 * 6.0,
        "first vertex path length {}",
        first[1].mean_path_length
    );
    assert!(a[1].mean_path_length > 2.0, "path tracing path length {}", a[1].mean_path_length);
}

#[test]
fn relative_threshold_without_a_first_record_path_traces() {
    // A sparse cache (one warm-up frame, 1% of primary vertices stored: a handful of records at
    // 32x18): most first hits have no record. A relative threshold has no brightness to scale
    // there; the path is path traced rather than cut at its first filled vertex (t · 0² = 0).
    // At a huge relative t every path is path traced: bit for bit the path tracing rule.
    let scene = room_scene();
    let sg = scene_gpu(&scene, 6);
    let sparse = |rule| TerminationSettings { warmup_frames: 1, ..settings(rule) };
    let render = |rule| {
        let mut cache = TerminationCache::new(gpu(), &sg, sparse(rule)).unwrap();
        (0..2).map(|f| cache.render(gpu(), &sg, &scene.camera, 5, f).unwrap()).collect::<Vec<_>>()
    };
    let a = render(TerminationRule::PathTracing);
    let b = render(TerminationRule::VarianceBounding { t: 1e30, relative: true });
    for f in 0..2 {
        let s = b[f].stats;
        eprintln!("frame {f}: {s:?}");
        // The case must occur: vertices without a record and filled records both.
        assert!(s.unknown > 0 && s.filled > 0, "frame {f}: not a sparse cache: {s:?}");
        let cut = a[f].path_length.iter().zip(&b[f].path_length).filter(|(x, y)| x != y).count();
        let differ = a[f].radiance.iter().zip(&b[f].radiance).filter(|(x, y)| x != y).count();
        assert!(
            cut == 0 && differ == 0,
            "frame {f}: relative t = 1e30 changed {differ} pixels and {cut} path lengths"
        );
    }
}

fn pt_mean_image(sg: &SceneGpu, spp: u32) -> Vec<f64> {
    let mut pt = PathTracer::new(gpu(), sg).expect("path tracer");
    pt.render(gpu(), sg, spp, 77, 0)
        .unwrap()
        .radiance
        .iter()
        .map(|c| (c[0] + c[1] + c[2]) as f64 / 3.0)
        .collect()
}

#[test]
fn path_length_grows_with_the_variance_threshold() {
    let scene = room_scene();
    let sg = scene_gpu(&scene, 6);
    // The room's records have a local variance around 1e-4 (radiance around 0.1).
    let lengths: Vec<f64> = [1e-6, 1e-5, 1e-4, 1e-3, 1e-2]
        .iter()
        .map(|&t| {
            let out = run(&sg, &scene, TerminationRule::VarianceBounding { t, relative: false }, 2);
            out[1].mean_path_length
        })
        .collect();
    eprintln!("path lengths by t: {lengths:?}");
    for k in 1..lengths.len() {
        assert!(lengths[k] >= lengths[k - 1], "path length by t: {lengths:?}");
    }
    assert!(lengths[4] > lengths[0] + 1.0, "path length by t: {lengths:?}");
}

#[test]
fn two_runs_give_the_same_bits_under_slot_contention() {
    // Every primary vertex offered (hundreds of new keys a frame) into 128 slots: keys compete
    // for the same empty slots in the same frame and probe windows overflow. A slot's index
    // seeds its propagation, so the slot each key gets, and which keys fail, must not depend on
    // the order invocations run in (a compare-exchange insertion gave them to whichever came
    // first). Images, path lengths, counters, slots and records must agree bit for bit.
    let scene = room_scene();
    let sg = scene_gpu(&scene, 6);
    let run = || {
        let s = TerminationSettings {
            capacity: 128,
            store_probability: 1.0,
            warmup_frames: 2,
            ..settings(TerminationRule::VarianceBounding { t: 1.0, relative: true })
        };
        let mut cache = TerminationCache::new(gpu(), &sg, s).expect("termination cache");
        let frames: Vec<TerminationOutput> = (0..4)
            .map(|f| cache.render(gpu(), &sg, &scene.camera, 5, f).expect("render"))
            .collect();
        (frames, cache.read_slots(gpu()).unwrap(), cache.read_records(gpu()).unwrap())
    };
    // Three runs: a race shows in some runs only (on lavapipe's two threads about one pair of
    // runs in five differed before the insertion in rounds).
    let (a, slots_a, records_a) = run();
    // The case must contend: failed insertions (a full table).
    assert!(a[1].stats.insert_failures > 0, "no contention: {:?}", a[1].stats);
    for run_b in 1..3 {
        let (b, slots_b, records_b) = run();
        for f in 0..4 {
            assert_eq!(a[f].stats, b[f].stats, "run {run_b}, frame {f}: counters");
            assert!(a[f].radiance == b[f].radiance, "run {run_b}, frame {f}: images differ");
            assert!(a[f].path_length == b[f].path_length, "run {run_b}, frame {f}: path lengths");
        }
        assert!(slots_a == slots_b, "run {run_b}: slot tables differ");
        assert!(records_a == records_b, "run {run_b}: records differ");
    }
}

#[test]
fn incomplete_samples_path_traced_make_the_first_estimates_complete() {
    // The furnace's records hold a·L = 0.5 (emission apart). One warm-up frame stores vertices
    // and the first frame propagates them into an empty cache: every sample's hit lacks a
    // record. Left out, an estimate reads 0 there and starts its record at the one-bounce
    // value a·Le = 0.25; path traced from the hit (12 bounces) it is a·L (1 − a^12) ≈ 0.5.
    let (scene, _) = furnace();
    let sg = scene_gpu(&scene, 12);
    let mean_record = |incomplete: Incomplete| {
        let s = TerminationSettings {
            incomplete,
            warmup_frames: 1,
            // Every primary vertex offered: many records after one warm-up frame.
            store_probability: 1.0,
            ..settings(TerminationRule::FirstVertex)
        };
        let mut cache = TerminationCache::new(gpu(), &sg, s).unwrap();
        let out = cache.render(gpu(), &sg, &scene.camera, 5, 0).unwrap();
        let records: Vec<f64> = cache
            .read_records(gpu())
            .unwrap()
            .into_iter()
            .filter(|r| r.vertices > 0.0)
            .map(|r| (r.mean[0] + r.mean[1] + r.mean[2]) as f64 / 3.0)
            .collect();
        assert!(records.len() > 20, "{incomplete:?}: only {} filled records", records.len());
        // Every propagated vertex had a sample without a record: the counter says so.
        assert_eq!(out.stats.propagated, 0, "{incomplete:?}: {:?}", out.stats);
        assert!(out.stats.incomplete > 20, "{incomplete:?}: {:?}", out.stats);
        records.iter().sum::<f64>() / records.len() as f64
    };
    let left_out = mean_record(Incomplete::LeaveOut);
    let traced = mean_record(Incomplete::PathTrace);
    eprintln!("first records' mean: left out {left_out}, path traced {traced}");
    // Bounds from the closed forms (0.25 and 0.5 less 0.5^13), halfway between them.
    assert!((left_out - 0.25).abs() < 0.125, "left out: {left_out}, expected 0.25");
    assert!((traced - 0.5).abs() < 0.125, "path traced: {traced}, expected 0.5");
}

#[test]
fn paper_conditions_k_samples_and_the_cache_mean_unit() {
    // The defaults are the paper's statistics: K = 32 samples per stored vertex (one BSDF ray
    // each, so a propagated vertex traces more than 32 rays; K = 4 traces at most 4 · 2 + 1),
    // and absolute thresholds in the cache's own mean radiance.
    let scene = room_scene();
    let sg = scene_gpu(&scene, 6);
    let defaults = TerminationSettings {
        rule: TerminationRule::VarianceBounding { t: 0.01, relative: false },
        capacity: 1 << 12,
        warmup_frames: 4,
        store_probability: 0.1,
        ..Default::default()
    };
    assert_eq!(defaults.radiance_scale, RadianceScale::CacheMean);
    let mut cache = TerminationCache::new(gpu(), &sg, defaults).unwrap();
    let out = cache.render(gpu(), &sg, &scene.camera, 5, 0).unwrap();
    let vertices = (out.stats.propagated + out.stats.incomplete) as f64;
    let per_vertex = out.stats.propagate_rays as f64 / vertices;
    eprintln!("defaults: {vertices} propagated vertices, {per_vertex:.2} rays each");
    assert!(vertices > 20.0, "{:?}", out.stats);
    assert!(per_vertex > 32.0, "K = {}: {per_vertex} rays per vertex", defaults.samples_per_vertex);
    // The unit is the mean luminance of the records the first image read (the room's are
    // around 0.1, far from 1).
    let unit = cache.radiance_unit(&defaults);
    eprintln!("derived radiance unit {unit}, records' mean {}", out.cache.mean);
    assert_eq!(unit, out.cache.mean);
    assert!(unit > 0.0 && unit < 0.5, "derived unit {unit}");
    // Stating that unit gives the same image, bit for bit; unit 1 (a threshold 1/unit² times
    // higher) gives longer paths: the derived unit is what the threshold reads.
    let stated = |radiance_unit: f64| {
        let s = TerminationSettings {
            radiance_scale: RadianceScale::Stated,
            radiance_unit,
            ..defaults
        };
        let mut c = TerminationCache::new(gpu(), &sg, s).unwrap();
        c.render(gpu(), &sg, &scene.camera, 5, 0).unwrap()
    };
    let same = stated(unit);
    assert!(same.radiance == out.radiance, "CacheMean and Stated({unit}) differ");
    let one = stated(1.0);
    eprintln!("path length: unit {unit} {}, unit 1 {}", out.mean_path_length, one.mean_path_length);
    assert!(one.mean_path_length > out.mean_path_length, "unit 1 should give longer paths");
}

#[test]
fn incomplete_estimates_included_update_filled_records() {
    // `Include` (the paper's propagation, which reads the cache at the hit whatever it holds)
    // folds an estimate with a sample that read an empty record into filled records too, where
    // `LeaveOut` lets it only start an empty one. In the furnace two frames after one warm-up
    // frame, filled records still receive such estimates: included, the records average more
    // vertices (their radiance then mixes in the samples that read filled records, where a
    // record left alone keeps its first, one-bounce estimate).
    let (scene, _) = furnace();
    let sg = scene_gpu(&scene, 12);
    let records = |incomplete: Incomplete| {
        let s = TerminationSettings {
            incomplete,
            warmup_frames: 1,
            store_probability: 1.0,
            ..settings(TerminationRule::FirstVertex)
        };
        let mut cache = TerminationCache::new(gpu(), &sg, s).unwrap();
        let out: Vec<_> =
            (0..2).map(|f| cache.render(gpu(), &sg, &scene.camera, 5, f).unwrap()).collect();
        assert!(out[1].stats.incomplete > 0, "{incomplete:?}: {:?}", out[1].stats);
        let filled: Vec<_> =
            cache.read_records(gpu()).unwrap().into_iter().filter(|r| r.vertices > 0.0).collect();
        let n = filled.len() as f64;
        let vertices = filled.iter().map(|r| r.vertices as f64).sum::<f64>() / n;
        let mean =
            filled.iter().map(|r| (r.mean[0] + r.mean[1] + r.mean[2]) as f64 / 3.0).sum::<f64>()
                / n;
        (vertices, mean)
    };
    let (v_out, m_out) = records(Incomplete::LeaveOut);
    let (v_in, m_in) = records(Incomplete::Include);
    eprintln!(
        "records: left out {v_out:.3} vertices, mean {m_out:.4}; included {v_in:.3}, {m_in:.4}"
    );
    assert!(v_in > v_out, "included estimates should add vertices: {v_in} vs {v_out}");
}
