//! The hash cache on the GPU: keys and table against the CPU reference (same keys, same
//! contents, probing bound, no duplicates, eviction of entries older than max_age), a furnace
//! converging to its analytic radiance through the cache, and stability against 1 spp.

use glam::Vec3;
use hash_cache::key::{self, NONE};
use hash_cache::table_cpu::{CpuHashTable, check_invariants};
use hash_cache::{HC_NEEDS_SAMPLE, HashCache, HashCacheLookup, HashCacheSettings};
use render::path_tracer::{PathTracer, PathTracerSettings};
use render::scene::SceneDesc;
use render::scene_gpu::SceneGpu;
use taa::{Taa, TaaSettings, resolve_cpu};

use common::{H, W, furnace, gpu, room_scene};
use testkit::test_scenes as common;

fn scene_gpu(scene: &SceneDesc, max_depth: u32) -> SceneGpu {
    SceneGpu::new(
        gpu(),
        scene,
        PathTracerSettings { width: W, height: H, max_depth, rr_start_depth: 3 },
    )
    .expect("scene")
}

#[test]
fn keys_table_and_eviction_match_the_cpu_reference() {
    for lookup in [HashCacheLookup::FirstHit, HashCacheLookup::SecondaryHit] {
        let mut scene = room_scene();
        let mut sg = scene_gpu(&scene, 3);
        // A small table (load around a quarter) so that home windows overlap, and max_age 1 so
        // that a moving camera evicts.
        let settings = HashCacheSettings {
            capacity: 4096,
            probe_limit: 16,
            max_age: 1,
            lookup,
            ..Default::default()
        };
        let mut cache = HashCache::new(gpu(), &sg, settings).expect("hash cache");
        let mut cpu = CpuHashTable::new(settings.capacity, settings.probe_limit, settings.max_age);
        let mut evictions = 0;
        for frame in 0..4u32 {
            scene.camera.position.x = 0.3 * frame as f32;
            sg.update(gpu(), &scene);
            let out = cache.render(gpu(), &sg, &scene.camera, 3, frame, None).expect("render");
            let stamp = frame + 1;
            let records = cache.read_records(gpu()).unwrap();
            let slots = cache.read_slots(gpu()).unwrap();
            let k = settings.key_params(&scene.camera, H);
            // Same keys as the CPU from the recorded key points (float ties at voxel borders aside).
            let (mut keyed, mut same) = (0, 0);
            let (occupied, evicted) = cpu.age(stamp);
            for r in &records {
                if r.flags & HC_NEEDS_SAMPLE == 0 {
                    continue;
                }
                keyed += 1;
                let p = Vec3::from(r.key_point);
                let n = Vec3::from(r.key_normal);
                let to = p - scene.camera.position;
                let level = key::level(&k, to.length(), n.dot(to) / to.length());
                let expected = key::key(&k, p, n, level, key::unpack2x16unorm(r.voxel_jitter));
                same += (expected.home == r.home && expected.checksum == r.checksum) as u32;
                assert_ne!(
                    r.slot, NONE,
                    "{lookup:?} frame {frame}: an insertion failed in a quarter-full table"
                );
                let s = slots[r.slot as usize];
                assert_eq!(
                    (s.checksum, s.home, s.last_access),
                    (r.checksum, r.home, stamp),
                    "{lookup:?} frame {frame}: slot {} of a pixel",
                    r.slot
                );
                let key = key::VoxelKey { home: r.home, checksum: r.checksum };
                cpu.find_or_insert(key, stamp).expect("cpu insertion");
            }
            assert!(
                keyed > (W * H) as usize / 2,
                "{lookup:?}: only {keyed} pixels have a key point"
            );
            assert!(
                same as f64 >= 0.995 * keyed as f64,
                "{lookup:?} frame {frame}: {same} of {keyed} GPU keys equal the CPU's"
            );
            check_invariants(&slots, settings.probe_limit)
                .unwrap_or_else(|e| panic!("{lookup:?} frame {frame}: {e}"));
            // Same contents (slots may differ: insertion order), same counters.
            assert_eq!(
                CpuHashTable::contents(slots.iter().copied()),
                CpuHashTable::contents(cpu.slots.iter().copied()),
                "{lookup:?} frame {frame}"
            );
            let inserted =
                CpuHashTable::contents(cpu.slots.iter().copied()).len() as u32 - occupied;
            assert_eq!(
                (out.stats.evicted, out.stats.occupied, out.stats.inserted),
                (evicted, occupied + inserted, inserted),
                "{lookup:?} frame {frame}"
            );
            assert_eq!(out.stats.insert_failures, 0);
            // Every live entry was accessed within max_age frames.
            assert!(
                slots
                    .iter()
                    .filter(|s| s.checksum != 0)
                    .all(|s| stamp - s.last_access <= settings.max_age)
            );
            evictions += evicted;
            // One claimant per accessed cell: update paths = distinct cells accessed this frame.
            let mut cells: Vec<u32> =
                records.iter().filter(|r| r.flags & HC_NEEDS_SAMPLE != 0).map(|r| r.slot).collect();
            cells.sort_unstable();
            cells.dedup();
            assert_eq!(out.stats.update_paths as usize, cells.len(), "{lookup:?} frame {frame}");
        }
        assert!(evictions > 0, "{lookup:?}: the moving camera evicted nothing");
    }
}

fn mean_relative_error(img: &[[f32; 4]], expected: f32) -> f64 {
    img.iter().map(|c| ((c[0] + c[1] + c[2]) / 3.0 - expected).abs() as f64).sum::<f64>()
        / img.len() as f64
        / expected as f64
}

#[test]
fn furnace_converges_to_the_analytic_radiance_through_the_cache() {
    let (scene, expected) = furnace();
    let sg = scene_gpu(&scene, 40);
    let mut pt = PathTracer::new(gpu(), &sg).expect("path tracer");
    let frames = 16;
    let pt_error = (0..4)
        .map(|f| mean_relative_error(&pt.render(gpu(), &sg, 1, 11, f).unwrap().radiance, expected))
        .sum::<f64>()
        / 4.0;
    for (lookup, seeds) in [
        (HashCacheLookup::FirstHit, &[11u64, 12, 13][..]),
        (HashCacheLookup::SecondaryHit, &[11, 12, 13][..]),
    ] {
        let (mut ratios, mut late_ratios) = (vec![], vec![]);
        for &seed in seeds {
            let mut cache =
                HashCache::new(gpu(), &sg, HashCacheSettings { lookup, ..Default::default() })
                    .expect("hash cache");
            let mut errors = vec![];
            let mut last = vec![];
            for frame in 0..frames {
                let out = cache.render(gpu(), &sg, &scene.camera, seed, frame, None).unwrap();
                errors.push(mean_relative_error(&out.radiance, expected));
                last = out.radiance;
            }
            // Unbiased: the image mean is the analytic radiance (3 % covers the 1 spp noise).
            let mean = last.iter().map(|c| c[0] as f64).sum::<f64>() / (W * H) as f64;
            assert!(
                (mean - expected as f64).abs() < 0.03 * expected as f64,
                "{lookup:?} seed {seed}: image mean {mean} expected {expected}"
            );
            let late = errors[frames as usize - 4..].iter().sum::<f64>() / 4.0;
            eprintln!(
                "{lookup:?} seed {seed}: per-pixel relative error {:.4} -> {:.4} (last 4 frames {late:.4}), 1 spp {pt_error:.4}",
                errors[0], errors[15]
            );
            assert!(
                late < errors[0] && late < pt_error,
                "{lookup:?}: per-pixel error by frame {errors:?}, 1 spp {pt_error}"
            );
            ratios.push(errors[15] / errors[0]);
            late_ratios.push(late / errors[0].min(pt_error));
        }
        // The relation above over the seeds, by a margin from their spread: the late error's
        // ratio to the smaller of frame 0's and 1 spp's has its one-sided 95% bound under 1.
        let bound = common::upper_bound_of_mean(&late_ratios);
        eprintln!(
            "{lookup:?}: late error / min(frame 0, 1 spp) per seed {late_ratios:.3?}, bound {bound:.3}"
        );
        assert!(bound < 1.0, "{lookup:?}: late error ratios {late_ratios:?}, bound {bound}");
        // The paper's first-hit lookup: the error of frame 15 is under half of frame 0's (one
        // sample per cell), bound over the seeds. The secondary-hit lookup keeps next-event
        // estimation at the primary hit uncached (fresh noise every frame), so it gains less:
        // 0.1285 -> 0.1042 (ratio 0.81) at seed 11, so only the ordering above is asserted for it
        // (over the same three seeds).
        if lookup == HashCacheLookup::FirstHit {
            let bound = common::upper_bound_of_mean(&ratios);
            eprintln!(
                "{lookup:?}: errors[15] / errors[0] per seed {ratios:.3?}, 95% bound of the mean {bound:.3}"
            );
            assert!(
                bound < 0.5,
                "{lookup:?}: errors[15] / errors[0] per seed {ratios:?}, bound {bound}"
            );
        }
    }
}

fn smape(a: &[[f32; 4]], b: &[[f32; 4]]) -> f64 {
    a.iter()
        .zip(b)
        .map(|(x, y)| {
            (0..3)
                .map(|c| ((x[c] - y[c]).abs() / (x[c].abs() + y[c].abs() + 0.01)) as f64)
                .sum::<f64>()
                / 3.0
        })
        .sum::<f64>()
        / a.len() as f64
}

#[test]
fn static_scene_flickers_less_than_1spp_and_is_deterministic() {
    let scene = room_scene();
    let sg = scene_gpu(&scene, 4);
    let mut pt = PathTracer::new(gpu(), &sg).expect("path tracer");
    let frames = 12;
    let pt_frames: Vec<_> =
        (0..frames).map(|f| pt.render(gpu(), &sg, 1, 5, f).unwrap().radiance).collect();
    let flicker = |v: &[Vec<[f32; 4]>]| {
        (6..frames as usize).map(|f| smape(&v[f], &v[f - 1])).sum::<f64>() / (frames as f64 - 6.0)
    };
    let pt_flicker = flicker(&pt_frames);
    for lookup in [HashCacheLookup::FirstHit, HashCacheLookup::SecondaryHit] {
        let run = || {
            let mut cache =
                HashCache::new(gpu(), &sg, HashCacheSettings { lookup, ..Default::default() })
                    .expect("hash cache");
            (0..frames)
                .map(|f| cache.render(gpu(), &sg, &scene.camera, 5, f, None).unwrap().radiance)
                .collect::<Vec<_>>()
        };
        let a = run();
        let hc_flicker = flicker(&a);
        assert!(
            hc_flicker < pt_flicker,
            "{lookup:?}: frame-to-frame SMAPE {hc_flicker} vs 1 spp {pt_flicker}"
        );
        eprintln!("{lookup:?}: frame-to-frame SMAPE {hc_flicker:.4} vs 1 spp {pt_flicker:.4}");
        if lookup == HashCacheLookup::SecondaryHit {
            assert!(a == run(), "{lookup:?}: two runs differ");
        }
    }
}

#[test]
fn taa_resolves_the_cache_colour() {
    let mut scene = room_scene();
    let mut sg = scene_gpu(&scene, 3);
    let settings = HashCacheSettings::default();
    let mut plain = HashCache::new(gpu(), &sg, settings).expect("hash cache");
    let mut under_taa = HashCache::new(gpu(), &sg, settings).expect("hash cache");
    let mut taa = Taa::new(gpu(), &sg, TaaSettings::default()).expect("taa");
    for frame in 0..3 {
        scene.camera.position.x = 0.05 * frame as f32;
        sg.update(gpu(), &scene);
        let a = plain.render(gpu(), &sg, &scene.camera, 9, frame, None).unwrap();
        let b = under_taa.render(gpu(), &sg, &scene.camera, 9, frame, Some(&mut taa)).unwrap();
        let i = taa.inspect(gpu()).unwrap();
        // TAA's input is the cache's colour and primary hits of this frame ...
        assert_eq!(i.current, a.radiance, "frame {frame}");
        assert_eq!(i.primary.iter().map(|p| p.motion).collect::<Vec<_>>(), a.motion);
        assert_eq!(b.timings.last().map(|t| t.pass.as_str()), Some(taa::TAA_RESOLVE_PASS));
        // ... and its output the resolve of it.
        let expected = resolve_cpu::resolve(
            &taa.settings(),
            (W, H),
            i.params_history_valid,
            &i.current,
            &i.primary,
            &i.previous_primary,
            &i.history,
        );
        for (g, c) in b.radiance.iter().zip(&expected) {
            assert!(
                (0..3).all(|k| (g[k] - c[k]).abs() <= 1e-4 * (1.0 + c[k].abs())),
                "frame {frame}: {g:?} vs {c:?}"
            );
        }
        assert_eq!(frame > 0, i.params_history_valid);
    }
}

/// Ray count of one frame on a lit plane filling the view (first-hit lookup, max_depth 1, no
/// Russian roulette): hc_trace traces one camera ray per pixel; each update path one shadow ray
/// and one continuation that escapes. The update starts from the hit hc_trace found: a third
/// ray per update path (the key ray traced again) is a defect.
#[test]
fn update_paths_start_at_the_traced_key_point() {
    use glam::{Mat4, Vec3};
    use render::scene::{Camera, Instance, Light, Material, Mesh};
    let scene = SceneDesc {
        meshes: vec![Mesh::plane(50.0)],
        materials: vec![Material {
            base_color: Vec3::splat(0.5),
            specular: 0.0,
            ..Default::default()
        }],
        instances: vec![Instance { mesh: 0, material: 0, transform: Mat4::IDENTITY }],
        lights: vec![Light::Directional {
            direction: Vec3::new(-0.3, -1.0, -0.2).normalize(),
            irradiance: Vec3::splat(3.0),
            angular_radius: 0.0,
        }],
        environment: Vec3::ZERO,
        camera: Camera {
            position: Vec3::new(0.0, 3.0, 0.0),
            target: Vec3::ZERO,
            up: Vec3::NEG_Z,
            vfov: 50f32.to_radians(),
        },
        ..Default::default()
    };
    let sg = scene_gpu(&scene, 1);
    let mut cache = HashCache::new(
        gpu(),
        &sg,
        HashCacheSettings { lookup: HashCacheLookup::FirstHit, ..Default::default() },
    )
    .expect("hash cache");
    for frame in 0..2 {
        let s = cache.render(gpu(), &sg, &scene.camera, 3, frame, None).unwrap().stats;
        assert!(s.update_paths > 0);
        assert_eq!(s.rays, W * H + 2 * s.update_paths, "frame {frame}: {s:?}");
    }
}

/// Radiance against the reference, the hash cache's twin of the sample cache's test: on a still
/// view of the room (max depth 3) the paper's first-hit cache converges towards the path-traced
/// reference (1024 spp): mean HDR-FLIP falls from frames 2 and 8 to frame 32, bound over 3
/// seeds (one-sided Student-t of the per-seed differences).
#[test]
fn still_view_converges_to_the_path_traced_reference() {
    let scene = room_scene();
    let sg = scene_gpu(&scene, 3);
    let mut pt = PathTracer::new(gpu(), &sg).expect("path tracer");
    let image = |rgba: &[[f32; 4]]| {
        metrics::Image::new(W, H, rgba.iter().map(|p| [p[0], p[1], p[2]]).collect())
    };
    let flip = |reference: &metrics::Image, rgba: &[[f32; 4]]| {
        metrics::flip_hdr(reference, &image(rgba), metrics::DEFAULT_PPD).mean
    };
    let reference = image(&pt.render(gpu(), &sg, 1024, 1, 0).expect("reference").radiance);
    let checkpoints = [2usize, 8, 32];
    let mut per_seed: Vec<[f64; 3]> = vec![];
    for seed in [3u64, 4, 5] {
        let mut cache =
            HashCache::new(gpu(), &sg, HashCacheSettings::default()).expect("hash cache");
        let mut at = [0.0; 3];
        for f in 0..32u32 {
            let out = cache.render(gpu(), &sg, &scene.camera, seed, f, None).unwrap();
            if let Some(i) = checkpoints.iter().position(|&c| c == f as usize + 1) {
                at[i] = flip(&reference, &out.radiance);
            }
        }
        per_seed.push(at);
    }
    eprintln!(
        "hash cache mean FLIP vs 1024 spp at frames {checkpoints:?} per seed: {per_seed:.4?}"
    );
    // Frame 2 to 8 is not asserted: measured +0.0027, -0.0123, -0.0196 (seeds 3-5), the bound of
    // the mean is above 0 (a cell's first samples and the jittered first hits' voxel noise
    // dominate early); from 8 to 32 and from 2 to 32 the error falls at every seed.
    for (a, b) in [(1, 2), (0, 2)] {
        let d: Vec<f64> = per_seed.iter().map(|x| x[b] - x[a]).collect();
        let bound = common::upper_bound_of_mean(&d);
        assert!(
            bound < 0.0,
            "FLIP from frame {} to {}: differences {d:?}, bound {bound}",
            checkpoints[a],
            checkpoints[b]
        );
    }
}
