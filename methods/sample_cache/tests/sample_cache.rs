//! The stable sample cache on small analytic scenes: mask invariants after every frame, static
//! views (samples stay in their pixels, counts conserved, deterministic shading converges), the
//! slope test against its CPU twin on planes and a depth step, density control, the adaptive
//! shading budget, and determinism; convergence to the path-traced reference on a still view
//! and nearness to per-frame references under motion (with the hash cache), TAA over the cache,
//! and the list passes' indirect dispatch against the direct one.

use glam::{Mat4, Vec2, Vec3};
use hash_cache::{HashCache, HashCacheSettings};
use render::frame::CameraBasis;
use render::gpu::Gpu;
use render::path_tracer::{PathTracer, PathTracerSettings};
use render::scene::{Camera, Instance, Light, Material, Mesh, SceneDesc};
use render::scene_gpu::SceneGpu;
use sample_cache::storage::{CachedHit, check_mask, occupancy, visibility};
use sample_cache::{
    CacheFrame, CacheState, FLAG_BASE, FLAG_HOLE, FLAG_SLOPE, LIST_WORKGROUP, MAX_GROUPS_X,
    Retrace, SampleCache, SampleCacheSettings, ShadingMode, SscSlot, list_dispatch, shading_rate,
    slope,
};
use std::sync::OnceLock;
use taa::{Taa, TaaSettings, resolve_cpu};

use testkit::test_scenes as common;

const W: u32 = 64;
const H: u32 = 36;
const SEED: u64 = 7;

fn gpu() -> &'static Gpu {
    static GPU: OnceLock<Gpu> = OnceLock::new();
    GPU.get_or_init(|| Gpu::new().expect("a wgpu adapter (lavapipe on CI)"))
}

fn top_down(height: f32) -> Camera {
    Camera {
        position: Vec3::new(0.0, height, 0.0),
        target: Vec3::ZERO,
        up: Vec3::NEG_Z,
        vfov: 50f32.to_radians(),
    }
}

fn oblique() -> Camera {
    Camera {
        position: Vec3::new(0.0, 1.0, 3.0),
        target: Vec3::new(0.0, 0.0, 1.2),
        up: Vec3::Y,
        vfov: 40f32.to_radians(),
    }
}

/// A lit ground plane, optionally with a raised square (a depth step) over the origin. Shading is
/// deterministic: one directional light of zero angular radius, no environment, max_depth 1 (and
/// the continuation ray escapes into a black environment).
fn scene(camera: Camera, step: bool) -> SceneDesc {
    let mut instances = vec![Instance { mesh: 0, material: 0, transform: Mat4::IDENTITY }];
    if step {
        instances.push(Instance {
            mesh: 1,
            material: 1,
            transform: Mat4::from_translation(Vec3::new(0.0, 0.6, 0.0)),
        });
    }
    SceneDesc {
        meshes: vec![Mesh::plane(50.0), Mesh::plane(0.5)],
        materials: vec![
            Material { base_color: Vec3::splat(0.5), specular: 0.0, ..Default::default() },
            Material { base_color: Vec3::new(0.9, 0.3, 0.2), specular: 0.0, ..Default::default() },
        ],
        instances,
        lights: vec![Light::Directional {
            direction: Vec3::new(-0.3, -1.0, -0.2).normalize(),
            irradiance: Vec3::splat(3.0),
            angular_radius: 0.0,
        }],
        environment: Vec3::ZERO,
        camera,
        ..Default::default()
    }
}

struct Rig {
    scene: SceneGpu,
    cache: SampleCache,
    frame: u32,
}

impl Rig {
    fn new(scene: &SceneDesc, settings: SampleCacheSettings) -> Self {
        let s = PathTracerSettings { width: W, height: H, max_depth: 1, rr_start_depth: 3 };
        let gpu_scene = SceneGpu::new(gpu(), scene, s).expect("scene");
        let cache = SampleCache::new(gpu(), &gpu_scene, settings).expect("sample cache");
        Self { scene: gpu_scene, cache, frame: 0 }
    }

    fn step(&mut self, scene: &SceneDesc) -> CacheFrame {
        self.scene.update(gpu(), scene);
        let out = self.cache.render(gpu(), &self.scene, SEED, self.frame).expect("cache frame");
        self.frame += 1;
        out
    }

    fn state(&self) -> CacheState {
        self.cache.read_state(gpu()).expect("cache state")
    }
}

fn settings(retrace: Retrace) -> SampleCacheSettings {
    SampleCacheSettings { retrace, ..Default::default() }
}

/// World position and geometric normal of a cached surface sample, on the CPU.
fn surface(scene: &SceneDesc, hit: CachedHit) -> Option<(Vec3, Vec3)> {
    let CachedHit::Surface { instance, primitive, barycentrics: b } = hit else { return None };
    let inst = scene.instances[instance as usize];
    let mesh = &scene.meshes[inst.mesh as usize];
    let [i0, i1, i2] = mesh.indices[primitive as usize];
    let (v0, v1, v2) =
        (mesh.positions[i0 as usize], mesh.positions[i1 as usize], mesh.positions[i2 as usize]);
    let p = (1.0 - b.x - b.y) * v0 + b.x * v1 + b.y * v2;
    let n = inst
        .transform
        .inverse()
        .transpose()
        .transform_vector3((v1 - v0).cross(v2 - v0))
        .normalize();
    Some((inst.transform.transform_point3(p), n))
}

fn check_invariants(state: &CacheState, n: u32) {
    for (p, &m) in state.masks.iter().enumerate() {
        if let Err(e) = check_mask(m, n) {
            panic!("pixel {p}: {e}");
        }
    }
}

fn max_abs_diff(a: &[[f32; 4]], b: &[[f32; 4]]) -> f32 {
    a.iter().zip(b).flat_map(|(x, y)| (0..3).map(move |c| (x[c] - y[c]).abs())).fold(0.0, f32::max)
}

#[test]
fn static_view_keeps_masks_samples_and_counts_and_converges() {
    let scene = scene(top_down(3.0), true);
    let basis = CameraBasis::new(&scene.camera, W, H);
    let s = settings(Retrace::Adaptive);
    let mut rig = Rig::new(&scene, s);
    let pixels = (W * H) as usize;
    let mut previous: Option<(CacheFrame, u32)> = None;
    let mut diffs = vec![];
    for f in 0..10 {
        let out = rig.step(&scene);
        let state = rig.state();
        check_invariants(&state, s.slots);
        // Every cached sample projects into the pixel that holds it.
        for (p, &m) in state.masks.iter().enumerate() {
            for slot in 0..s.slots {
                if occupancy(m, s.slots) >> slot & 1 == 0 {
                    continue;
                }
                let (world, _) = surface(&scene, state.slots[slot as usize * pixels + p].decode())
                    .expect("no background in this view");
                let at = basis.project(world, W, H).expect("in front of the camera");
                let own = Vec2::new((p as u32 % W) as f32, (p as u32 / W) as f32);
                assert!(
                    at.x >= own.x && at.x < own.x + 1.0 && at.y >= own.y && at.y < own.y + 1.0,
                    "frame {f} pixel {p} slot {slot}: sample at {at}"
                );
            }
        }
        let occupied: u32 = state.masks.iter().map(|&m| occupancy(m, s.slots).count_ones()).sum();
        assert_eq!(out.stats.occupied, occupied, "frame {f}: counter vs masks");
        if let Some((prev, prev_occupied)) = &previous {
            // Static: nothing leaves the screen, nothing loses its slot.
            assert_eq!(out.stats.dropped, 0, "frame {f}");
            assert_eq!(out.stats.reprojected, *prev_occupied, "frame {f}: samples not conserved");
            diffs.push(max_abs_diff(&out.radiance, &prev.radiance));
        }
        previous = Some((out, occupied));
    }
    // Deterministic shading: once every sample has been shaded the image stops changing.
    let last = *diffs.last().unwrap();
    assert!(last <= 1e-6, "frame-to-frame differences {diffs:?}");
    assert!(diffs[0] > last, "frame-to-frame differences {diffs:?}");
}

/// The slope test of the GPU against its CPU twin, on a static view where the reserved state of
/// frame f + 1 is the final state of frame f. Returns the GPU flags of frame f + 1.
fn slope_flags_match_cpu(scene: &SceneDesc, frames: u32) -> Vec<u32> {
    let s = settings(Retrace::Adaptive);
    let mut rig = Rig::new(scene, s);
    for _ in 0..frames {
        rig.step(scene);
    }
    let state = rig.state();
    let out = rig.step(scene);
    assert_eq!(out.stats.dropped, 0);
    let pixels = (W * H) as usize;
    let n = s.slots;
    let phi = slope::pixel_diagonal_angle(scene.camera.vfov, H);
    // Each pixel's closest visible sample (depth, Δn) and farthest visible depth.
    let eye = scene.camera.position;
    let per_pixel: Vec<(slope::Closest, f32)> = (0..pixels)
        .map(|p| {
            let vis = visibility(state.masks[p], n) & occupancy(state.masks[p], n);
            let samples: Vec<slope::Closest> = (0..n)
                .filter(|s| vis >> s & 1 == 1)
                .map(|slot| {
                    let (x, normal) =
                        surface(scene, state.slots[slot as usize * pixels + p].decode()).unwrap();
                    let t = (x - eye).length();
                    slope::Closest {
                        t,
                        slope: slope::slope(t, normal.dot((x - eye) / t).abs(), phi),
                    }
                })
                .collect();
            let far = samples.iter().map(|c| c.t).fold(0.0, f32::max);
            (slope::Closest::of(samples), far)
        })
        .collect();
    let mut disagreements = 0;
    for p in 0..pixels {
        let (x, y) = ((p as u32 % W) as i32, (p as u32 / W) as i32);
        let neighbourhood: Vec<(slope::Closest, f32)> = (-1..=1)
            .flat_map(|dy| (-1..=1).map(move |dx| (x + dx, y + dy)))
            .filter(|&(qx, qy)| qx >= 0 && qy >= 0 && qx < W as i32 && qy < H as i32)
            .map(|(qx, qy)| per_pixel[(qy as u32 * W + qx as u32) as usize])
            .collect();
        let expected = slope::flagged(per_pixel[p], neighbourhood.iter().copied(), s.epsilon1);
        let got = out.flags[p] & FLAG_SLOPE != 0;
        if expected != got {
            // Only a float's worth from the threshold may go either way, in one of the pairs.
            let (own, own_far) = per_pixel[p];
            let near_threshold = |c: slope::Closest, far: f32| {
                let bound = (1.0 + s.epsilon1) * (c.t + 2.0 * c.slope);
                (far - bound).abs() < 1e-5 * bound
            };
            assert!(
                neighbourhood
                    .iter()
                    .any(|&(c, far)| near_threshold(own, far) || near_threshold(c, own_far)),
                "pixel ({x}, {y}): CPU {expected}, GPU {got}"
            );
            disagreements += 1;
        }
        // The base grid of this frame, and no holes in a converged view.
        let k = (frames % 16) as i32;
        assert_eq!(
            out.flags[p] & FLAG_BASE != 0,
            x % 4 == k % 4 && y % 4 == k / 4,
            "pixel ({x}, {y})"
        );
        assert_eq!(out.flags[p] & FLAG_HOLE, 0);
    }
    assert!(disagreements <= 2, "{disagreements} borderline pixels");
    out.flags
}

#[test]
fn slope_test_flags_only_the_base_grid_on_planes() {
    for camera in [top_down(3.0), oblique()] {
        let flags = slope_flags_match_cpu(&scene(camera, false), 3);
        let flagged = flags.iter().filter(|&&f| f & FLAG_SLOPE != 0).count();
        assert_eq!(flagged, 0, "camera {camera:?}: {flagged} pixels flagged on a plane");
    }
}

#[test]
fn slope_test_flags_the_pixels_along_a_depth_step() {
    let scene = scene(top_down(3.0), true);
    let flags = slope_flags_match_cpu(&scene, 3);
    // Where the raised square's outline is (projected on the CPU): flagged pixels hug it.
    let basis = CameraBasis::new(&scene.camera, W, H);
    let corners: Vec<Vec2> = [(-0.5, -0.5), (0.5, -0.5), (0.5, 0.5), (-0.5, 0.5)]
        .iter()
        .map(|&(x, z)| basis.project(Vec3::new(x, 0.6, z), W, H).unwrap())
        .collect();
    let (lo, hi) = (
        corners.iter().fold(Vec2::MAX, |a, &c| a.min(c)),
        corners.iter().fold(Vec2::MIN, |a, &c| a.max(c)),
    );
    // [raised side, far side]: outline pixels and how many of them are flagged.
    let mut on_edge = [0u32; 2];
    let mut on_edge_flagged = [0u32; 2];
    for (p, &flag) in flags.iter().enumerate().take((W * H) as usize) {
        let c = Vec2::new((p as u32 % W) as f32 + 0.5, (p as u32 / W) as f32 + 0.5);
        // Chebyshev distance (pixels) from the pixel centre to the square's outline.
        let inside = c.cmpge(lo).all() && c.cmple(hi).all();
        let d = if inside {
            (c - lo).min(hi - c).min_element()
        } else {
            (lo - c).max(c - hi).max(Vec2::ZERO).max_element()
        };
        let flagged = flag & FLAG_SLOPE != 0;
        if flagged {
            assert!(d <= 2.5, "pixel {p} flagged {d} pixels from the step");
        }
        // Pixels along the outline on either side: the 3x3 of a raised-side pixel reaches the
        // ground, that of a ground pixel the square (§3.4: both sides of the edge are retraced,
        // so that an occluder's edge propagates into pixels that hold only ground samples).
        // Either fails only when every sample of the straddling neighbours fell on one side
        // (rare: the exact per-pixel check against the CPU twin is in slope_flags_match_cpu).
        if d < 1.0 {
            let side = usize::from(!inside);
            on_edge[side] += 1;
            on_edge_flagged[side] += flagged as u32;
        }
    }
    for (side, name) in ["raised", "far"].iter().enumerate() {
        assert!(on_edge[side] > 20, "{} {name}-side outline pixels", on_edge[side]);
        assert!(
            on_edge_flagged[side] as f32 >= 0.9 * on_edge[side] as f32,
            "{} of {} {name}-side outline pixels flagged",
            on_edge_flagged[side],
            on_edge[side]
        );
    }
}

/// Density control purges what it counts (section 3.2: the visible density): a still plane
/// whose every pixel holds 7 visible samples and 2 invisible ones (copies of its converged
/// samples) is above n_target + δ everywhere, so each pixel purges 7 − n_target = 3 samples,
/// all of them visible. A pixel that retraces nothing (no base rate, no slope flag) then ends
/// the frame with exactly n_target visible samples and its 2 invisible ones.
#[test]
fn density_control_purges_the_visible_samples_it_counts() {
    let scene = scene(top_down(3.0), false);
    let s = settings(Retrace::Adaptive);
    let mut rig = Rig::new(&scene, s);
    for _ in 0..4 {
        rig.step(&scene);
    }
    let converged = rig.state();
    let pixels = (W * H) as usize;
    let n = s.slots;
    let (visible, invisible) = (7usize, 2usize);
    let mut crowded = CacheState { masks: vec![0; pixels], slots: converged.slots.clone() };
    for p in 0..pixels {
        let own: Vec<SscSlot> = (0..n as usize)
            .filter(|&i| {
                visibility(converged.masks[p], n) & occupancy(converged.masks[p], n) >> i & 1 == 1
            })
            .map(|i| converged.slots[i * pixels + p])
            .collect();
        assert!(!own.is_empty(), "pixel {p} has no visible sample");
        for i in 0..visible + invisible {
            crowded.slots[i * pixels + p] = own[i % own.len()];
        }
        crowded.masks[p] = ((1 << (visible + invisible)) - 1) | (((1 << visible) - 1) << n);
    }
    rig.cache.write_state(gpu(), &crowded).expect("write state");
    let out = rig.step(&scene);
    assert_eq!(out.stats.dropped, 0);
    let state = rig.state();
    check_invariants(&state, n);
    let purge =
        -sample_cache::density::adjustment(visible as f32, visible as u32, s.n_target, s.delta);
    assert_eq!(purge, 3);
    assert_eq!(out.stats.purged, purge as u32 * pixels as u32, "purged samples");
    let mut checked = 0;
    for p in 0..pixels {
        if out.flags[p] != 0 {
            continue;
        }
        let m = state.masks[p];
        let (vis, occ) =
            ((visibility(m, n) & occupancy(m, n)).count_ones(), occupancy(m, n).count_ones());
        assert_eq!(
            (vis, occ - vis),
            (visible as u32 - purge as u32, invisible as u32),
            "pixel {p}: (visible, invisible) samples after the purge"
        );
        checked += 1;
    }
    assert!(checked as f32 > 0.9 * pixels as f32, "{checked} pixels without retraces");
}

#[test]
fn density_stays_within_bounds_and_runs_are_deterministic() {
    let s = settings(Retrace::Adaptive);
    let run = || {
        let mut scene = scene(top_down(3.0), true);
        let mut rig = Rig::new(&scene, s);
        let mut images = vec![];
        // Zoom in (samples spread out: holes) then out (they crowd), then hold still: after four
        // still frames the density control has settled.
        for f in 0..16 {
            let h = if f < 4 {
                3.0 - 0.15 * f as f32
            } else if f < 8 {
                2.4 + 0.25 * (f - 4) as f32
            } else {
                3.4
            };
            scene.camera = top_down(h);
            let out = rig.step(&scene);
            let state = rig.state();
            check_invariants(&state, s.slots);
            let out_stats = out.stats.clone();
            images.push(out.radiance);
            if f >= 12 {
                let vis: Vec<f32> = state
                    .masks
                    .iter()
                    .map(|&m| (visibility(m, s.slots) & occupancy(m, s.slots)).count_ones() as f32)
                    .collect();
                let mut outside = 0;
                for y in 0..H as i32 {
                    for x in 0..W as i32 {
                        let (mut sum, mut count) = (0.0, 0.0);
                        for (dx, dy) in (-1..=1).flat_map(|dy| (-1..=1).map(move |dx| (dx, dy))) {
                            let (qx, qy) = (x + dx, y + dy);
                            if qx >= 0 && qy >= 0 && qx < W as i32 && qy < H as i32 {
                                sum += vis[(qy * W as i32 + qx) as usize];
                                count += 1.0;
                            }
                        }
                        let density = sum / count;
                        if density < s.n_target - s.delta || density > s.n_target + s.delta {
                            outside += 1;
                        }
                    }
                }
                if outside > 0 {
                    let mut hist = [0u32; 13];
                    for &v in &vis {
                        hist[(v as usize).min(12)] += 1;
                    }
                    eprintln!(
                        "frame {f}: per-pixel visible counts {hist:?}, stats {:?}",
                        out_stats
                    );
                }
                assert_eq!(outside, 0, "frame {f}: {outside} pixels outside n_target ± δ");
            }
        }
        images
    };
    let a = run();
    let b = run();
    assert!(a == b, "two runs with the same seed differ");
}

#[test]
fn full_pixels_keep_the_same_samples_in_every_run() {
    // The camera backs away from the plane to 64 times its height in one frame: the whole last
    // image lands in a pixel or two, whose reservations then come from every workgroup of the
    // dispatch (threads on all of the adapter's cores contend), and each keeps N = 12. Which ones it
    // keeps must not depend on the order the reservation's threads run in (listing 2's race
    // kept whichever came first); under adaptive shading the kept samples' counts then decide
    // the histogram, the budget and which samples are shaded. Two runs must agree bit for bit:
    // images, counters, masks and slots.
    let s = SampleCacheSettings {
        shading: ShadingMode::Adaptive,
        shading_rate: 0.7,
        ..settings(Retrace::Adaptive)
    };
    let run = || {
        let mut scene = scene(top_down(1.0), true);
        let mut rig = Rig::new(&scene, s);
        [1.0, 1.0, 64.0, 64.0]
            .map(|h| {
                scene.camera = top_down(h);
                let out = rig.step(&scene);
                let state = rig.state();
                (out.radiance, out.stats, state.masks, state.slots)
            })
            .to_vec()
    };
    let (a, b) = (run(), run());
    // The case must overflow pixels: nothing leaves the image when backing away, so every
    // dropped sample is one a full pixel did not keep.
    assert!(a[2].1.dropped > 1000, "no full pixels: {:?}", a[2].1);
    for (f, (x, y)) in a.iter().zip(&b).enumerate() {
        assert_eq!(x.1, y.1, "frame {f}: counters differ");
        assert!(x.2 == y.2, "frame {f}: masks differ");
        assert!(x.3 == y.3, "frame {f}: slots differ");
        assert!(x.0 == y.0, "frame {f}: images differ");
    }
}

/// Visible (or all occupied) samples of pixel p: (hit, c_s).
fn samples(state: &CacheState, p: usize, n: u32, visible_only: bool) -> Vec<([u32; 4], f32)> {
    let pixels = state.masks.len();
    let mut set = occupancy(state.masks[p], n);
    if visible_only {
        set &= visibility(state.masks[p], n);
    }
    (0..n)
        .filter(|s| set >> s & 1 == 1)
        .map(|s| state.slots[s as usize * pixels + p])
        .map(|slot| (slot.hit, slot.radiance[3]))
        .collect()
}

fn visible_samples(state: &CacheState, p: usize, n: u32) -> Vec<([u32; 4], f32)> {
    samples(state, p, n, true)
}

/// Adaptive shading (section 3.5) on a still view at a 50% budget: the GPU's threshold is the
/// CPU's on the same histogram, the dispatch count is the budget up to the coin tosses' spread,
/// every pixel ends the frame with a shaded visible sample (else it would reconstruct nothing),
/// and the budget goes to the samples with the fewest shades: each sample's bucket is computed
/// here on the CPU from its c_s before the frame with the paper's importance 1 / (1 + c_s), and
/// every sample above the GPU's threshold bucket must have been shaded, none below it.
#[test]
fn adaptive_shading_dispatches_the_budget_to_low_counts_first() {
    let scene = scene(oblique(), true);
    let s = SampleCacheSettings {
        shading: ShadingMode::Adaptive,
        shading_rate: 0.5,
        ..Default::default()
    };
    let mut rig = Rig::new(&scene, s);
    let pixels = (W * H) as usize;
    let budget = s.shading_rate * pixels as f32;
    let mut total_dev = 0.0f64;
    let mut total_var = 0.0f64;
    let mut before: Option<CacheState> = None;
    // Mean c_s before the frame of the samples the budget shaded and of those it left.
    let (mut shaded_c, mut left_c) = ((0.0f64, 0u32), (0.0f64, 0u32));
    for f in 0..8 {
        let out = rig.step(&scene);
        let st = &out.stats;
        let after = rig.state();
        // The GPU's threshold is the CPU's on the same histogram.
        let dynamic = (budget - st.base_shaded as f32).max(0.0);
        let (t, coin) = shading_rate::threshold(&st.histogram, dynamic);
        assert_eq!(st.threshold, t, "frame {f}: histogram {:?}", st.histogram);
        assert!((st.coin - coin).abs() < 1e-5, "frame {f}: coin {} vs {coin}", st.coin);
        let expected =
            st.base_shaded as f32 + shading_rate::expected_dispatch(&st.histogram, dynamic);
        let total: u32 = st.histogram.iter().sum();
        if f >= 1 {
            assert!(total as f32 > budget, "frame {f}: only {total} candidates");
            assert!(
                (expected - budget).abs() < 1.0,
                "frame {f}: expected {expected} vs budget {budget}"
            );
        }
        // Dispatch count: binomial in the threshold bucket around the expectation.
        let n_t = st.histogram[t as usize] as f64;
        total_dev += st.shaded as f64 - expected as f64;
        total_var += n_t * coin as f64 * (1.0 - coin as f64);
        let sigma = (n_t * coin as f64 * (1.0 - coin as f64)).sqrt();
        assert!(
            (st.shaded as f64 - expected as f64).abs() <= 5.0 * sigma + 1.0,
            "frame {f}: shaded {} expected {expected} σ {sigma}",
            st.shaded
        );
        for p in 0..pixels {
            let now = visible_samples(&after, p, s.slots);
            assert!(
                now.iter().any(|v| v.1 > 0.0),
                "frame {f} pixel {p}: no shaded visible sample among {now:?}"
            );
        }
        if let Some(prev) = &before {
            let (lo, hi) = st.importance_bounds;
            for p in 0..pixels {
                let old = samples(prev, p, s.slots, false);
                let c_before: Vec<f32> = visible_samples(&after, p, s.slots)
                    .iter()
                    .map(|(hit, _)| old.iter().find(|o| o.0 == *hit).map_or(0.0, |o| o.1))
                    .collect();
                // Pixels with a sample shaded outside the budget: the base pixel, and a pixel
                // whose visible samples were all unshaded.
                if out.flags[p] & FLAG_BASE != 0 || c_before.iter().all(|&c| c == 0.0) {
                    continue;
                }
                for (&(_, c_after), &c) in visible_samples(&after, p, s.slots).iter().zip(&c_before)
                {
                    let shaded = c_after == c + 1.0;
                    assert!(shaded || c_after == c, "frame {f} pixel {p}: c_s {c} -> {c_after}");
                    // The bucket, either side of a float's worth from a bucket border.
                    let w = 1.0 / (1.0 + c);
                    let (b0, b1) = (
                        shading_rate::bucket(w * (1.0 - 1e-5), lo, hi, s.buckets),
                        shading_rate::bucket(w * (1.0 + 1e-5), lo, hi, s.buckets),
                    );
                    assert!(
                        if b0 > t {
                            shaded
                        } else if b1 < t {
                            !shaded
                        } else {
                            true
                        },
                        "frame {f} pixel {p}: c_s {c} (bucket {b0}..={b1}, threshold {t}) shaded {shaded}"
                    );
                    let acc = if shaded { &mut shaded_c } else { &mut left_c };
                    acc.0 += c as f64;
                    acc.1 += 1;
                }
            }
        }
        before = Some(after);
    }
    assert!(
        total_dev.abs() <= 4.0 * total_var.sqrt() + 1.0,
        "bias {total_dev} over 8 frames, σ {}",
        total_var.sqrt()
    );
    let (ms, ml) = (shaded_c.0 / shaded_c.1 as f64, left_c.0 / left_c.1 as f64);
    eprintln!(
        "mean c_s before the frame: shaded {ms:.2} ({} samples), left {ml:.2} ({})",
        shaded_c.1, left_c.1
    );
    assert!(shaded_c.1 > 100 && left_c.1 > 100 && ms < ml, "shaded {shaded_c:?} left {left_c:?}");
}

/// Radiance, not only stability: on a still view of a room lit mostly indirectly (tests/common,
/// max depth 3) the cache's image converges to the path-traced reference (1024 spp): the mean
/// HDR-FLIP against it falls from frame 2 to 8 to 32, each step bound over 3 seeds (one-sided
/// Student-t of the per-seed differences), and at frame 32 it is below 4 spp path tracing's.
/// A frozen or biased cache fails this; the flicker relations alone would pass it.
#[test]
fn still_view_converges_to_the_path_traced_reference() {
    let (w, h) = (common::W, common::H);
    let scene = common::room_scene();
    let sg = SceneGpu::new(
        gpu(),
        &scene,
        PathTracerSettings { width: w, height: h, max_depth: 3, rr_start_depth: 3 },
    )
    .expect("scene");
    let mut tracer = PathTracer::new(gpu(), &sg).expect("path tracer");
    let image = |rgba: &[[f32; 4]]| {
        metrics::Image::new(w, h, rgba.iter().map(|p| [p[0], p[1], p[2]]).collect())
    };
    let flip = |reference: &metrics::Image, rgba: &[[f32; 4]]| {
        metrics::flip_hdr(reference, &image(rgba), metrics::DEFAULT_PPD).mean
    };
    let reference = image(&tracer.render(gpu(), &sg, 1024, 1, 0).expect("reference").radiance);
    let checkpoints = [2usize, 8, 32];
    let mut per_seed: Vec<[f64; 3]> = vec![];
    let mut pt4 = vec![];
    for seed in [3u64, 4, 5] {
        let mut cache =
            SampleCache::new(gpu(), &sg, SampleCacheSettings::default()).expect("sample cache");
        let mut at = [0.0; 3];
        for f in 0..32u32 {
            let out = cache.render(gpu(), &sg, seed, f).expect("cache frame");
            if let Some(i) = checkpoints.iter().position(|&c| c == f as usize + 1) {
                at[i] = flip(&reference, &out.radiance);
            }
        }
        pt4.push(flip(&reference, &tracer.render(gpu(), &sg, 4, seed, 0).expect("4 spp").radiance));
        per_seed.push(at);
    }
    eprintln!(
        "sample cache mean FLIP vs 1024 spp at frames {checkpoints:?} per seed: {per_seed:.4?}; 4 spp {pt4:.4?}"
    );
    for k in 0..2 {
        let d: Vec<f64> = per_seed.iter().map(|a| a[k + 1] - a[k]).collect();
        let bound = common::upper_bound_of_mean(&d);
        assert!(
            bound < 0.0,
            "FLIP from frame {} to {}: differences {d:?}, bound {bound}",
            checkpoints[k],
            checkpoints[k + 1]
        );
    }
    let d: Vec<f64> = per_seed.iter().zip(&pt4).map(|(a, p)| a[2] - p).collect();
    assert!(common::upper_bound_of_mean(&d) < 0.0, "frame 32 vs 4 spp: differences {d:?}");
}

/// The weight of each sample's last shade: deterministic shading (one delta light, max depth 1,
/// black environment) makes every shade return the same radiance L; doubling the light after
/// `frames` frames then makes one shade move a sample from L to L + a·(2L − L), which measures
/// the weight a exactly. Checks a against `expected(α_GGX, c_s)` for every sample shaded in that
/// frame whose c_s (before it) is at least `min_count`; returns how many it checked per material.
fn check_blend_weights(
    mut scene: SceneDesc,
    s: SampleCacheSettings,
    frames: u32,
    min_count: f32,
    expected: impl Fn(f32, f32) -> f32,
) -> [u32; 2] {
    let mut rig = Rig::new(&scene, s);
    for _ in 0..frames {
        rig.step(&scene);
    }
    let before = rig.state();
    let Light::Directional { irradiance, .. } = &mut scene.lights[0] else { unreachable!() };
    *irradiance *= 2.0;
    rig.step(&scene);
    let after = rig.state();
    let pixels = (W * H) as usize;
    let mut checked = [0u32; 2];
    for p in 0..pixels {
        let old = samples(&before, p, s.slots, false);
        for slot in 0..s.slots as usize {
            if occupancy(after.masks[p], s.slots) >> slot & 1 == 0 {
                continue;
            }
            let now = after.slots[slot * pixels + p];
            let Some(&(_, c)) = old.iter().find(|o| o.0 == now.hit) else { continue };
            let prev = before.slots[(0..s.slots as usize)
                .find(|&q| before.slots[q * pixels + p].hit == now.hit)
                .unwrap()
                * pixels
                + p];
            // Shaded this frame, old enough, lit.
            if now.radiance[3] != c + 1.0 || c < min_count || prev.radiance[0] < 1e-3 {
                continue;
            }
            let CachedHit::Surface { instance, .. } = now.decode() else { continue };
            let material = scene.instances[instance as usize].material as usize;
            let a_ggx = scene.materials[material].roughness.powi(2);
            let want = expected(a_ggx, c);
            let a = now.radiance[0] / prev.radiance[0] - 1.0;
            assert!(
                (a - want).abs() < 1e-3,
                "pixel {p} slot {slot}: weight {a}, expected {want} (α_GGX {a_ggx}, c_s {c})"
            );
            checked[material] += 1;
        }
    }
    checked
}

/// App. C's temporal filter: with `roughness_alpha` a sample's blend weight is at least
/// α_min = (1 − α_GGX)·0.5 + α_GGX·0.1 of its material (GGX α = roughness²).
#[test]
fn roughness_sets_the_minimum_blend_weight() {
    let mut scene = scene(top_down(3.0), true);
    // The paper's glossy roughnesses: α_GGX 0.4 (ground) and 0.2 (raised square).
    scene.materials[0].roughness = 0.4f32.sqrt();
    scene.materials[1].roughness = 0.2f32.sqrt();
    let s = SampleCacheSettings { roughness_alpha: true, ..Default::default() };
    // Past the running-mean phase: 1 / (c + 1) <= 1/3 < α_min (0.34 and 0.42).
    let checked =
        check_blend_weights(scene, s, 12, 2.0, |a_ggx, _| (1.0 - a_ggx) * 0.5 + a_ggx * 0.1);
    assert!(checked.iter().all(|&n| n > 20), "samples checked per material {checked:?}");
}

/// The paper's main results accumulate a plain running mean (§3.3; α_min is App. C's
/// extension): by default a sample's weight is 1 / (c_s + 1) however often it was shaded,
/// checked where a floor of 0.1 (§5.2's glossy test) would differ, c_s >= 10.
#[test]
fn default_blend_weight_is_the_running_mean() {
    let s = SampleCacheSettings::default();
    // Uniform shading: about one shade per sample every n_target = 4 frames.
    let checked =
        check_blend_weights(scene(top_down(3.0), true), s, 48, 10.0, |_, c| 1.0 / (c + 1.0));
    assert!(checked.iter().sum::<u32>() > 20, "samples checked per material {checked:?}");
}

/// TAA over the sample cache (`SampleCache::resolve_taa`, the paper's error
/// figures run every method under TAA). Under a moving camera: TAA's input is the cache's image
/// and, per pixel, the primary attributes of the pixel's closest visible sample (instance,
/// depth, oriented normal, motion, checked here on the CPU from the cache's state); its output
/// is the CPU resolve of that input; and the history survives the rejection test on most pixels
/// (attributes that did not describe the pixel's surface would reject it everywhere).
#[test]
fn taa_resolves_the_cache_image_with_its_closest_samples() {
    let (w, h) = (common::W, common::H);
    let mut scene = common::room_scene();
    let mut sg = SceneGpu::new(
        gpu(),
        &scene,
        PathTracerSettings { width: w, height: h, max_depth: 3, rr_start_depth: 3 },
    )
    .expect("scene");
    let settings = SampleCacheSettings { taa: true, ..Default::default() };
    let mut cache = SampleCache::new(gpu(), &sg, settings).expect("sample cache");
    let mut taa = Taa::new(gpu(), &sg, TaaSettings::default()).expect("taa");
    for frame in 0..4u32 {
        scene.camera.position.x = 0.05 * frame as f32;
        sg.update(gpu(), &scene);
        let out = cache.render(gpu(), &sg, 9, frame).expect("cache frame");
        let resolved = cache.resolve_taa(gpu(), &mut taa).expect("resolve");
        assert_eq!(resolved.timings.last().map(|t| t.pass.as_str()), Some(taa::TAA_RESOLVE_PASS));
        let i = taa.inspect(gpu()).expect("inspect");
        assert_eq!(i.current, out.radiance, "frame {frame}: TAA's input is the cache's image");
        assert_eq!(
            i.primary.iter().map(|p| p.motion).collect::<Vec<_>>(),
            out.motion,
            "frame {frame}"
        );
        let expected = resolve_cpu::resolve(
            &taa.settings(),
            (w, h),
            i.params_history_valid,
            &i.current,
            &i.primary,
            &i.previous_primary,
            &i.history,
        );
        for (k, (g, c)) in resolved.radiance.iter().zip(&expected).enumerate() {
            assert!(
                (0..3).all(|ch| (g[ch] - c[ch]).abs() <= 1e-4 * (1.0 + c[ch].abs())),
                "frame {frame} pixel {k}: GPU {g:?} CPU {c:?}"
            );
        }
        let state = cache.read_state(gpu()).expect("state");
        let eye = scene.camera.position;
        for (p, prim) in i.primary.iter().enumerate() {
            let closest = visible_samples(&state, p, settings.slots)
                .into_iter()
                .filter_map(|(hit, _)| {
                    surface(&scene, SscSlot { hit, radiance: [0.0; 4] }.decode())
                        .map(|s| (hit[0], s))
                })
                .fold(None, |best: Option<(u32, (Vec3, Vec3))>, c| match best {
                    Some(b) if (b.1.0 - eye).length() <= (c.1.0 - eye).length() => Some(b),
                    _ => Some(c),
                });
            let Some((instance, (position, normal))) = closest else {
                assert_eq!(
                    prim.instance,
                    render::path_tracer::NO_HIT,
                    "frame {frame} pixel {p}: no visible sample"
                );
                continue;
            };
            let depth = (position - eye).length();
            let facing = if normal.dot(eye - position) < 0.0 { -normal } else { normal };
            assert_eq!(prim.instance, instance, "frame {frame} pixel {p}");
            assert!(
                (prim.depth - depth).abs() <= 1e-4 * depth,
                "frame {frame} pixel {p}: depth {} vs {depth}",
                prim.depth
            );
            assert!(
                Vec3::from(prim.normal).dot(facing) > 0.999,
                "frame {frame} pixel {p}: normal {:?} vs {facing}",
                prim.normal
            );
        }
        if frame > 0 {
            let kept = resolved.history_length.iter().filter(|&&l| l > 1.0).count() as f64
                / (w * h) as f64;
            eprintln!("frame {frame}: history kept on {kept:.3} of the pixels");
            assert!(kept > 0.9, "frame {frame}: history kept on {kept} of the pixels");
        }
    }
}

/// Under a moving camera, mean HDR-FLIP of each cache against a path-traced
/// reference of the same frame (256 spp, frames 5, 8 and 11 of 12; the room at 32x18, the
/// camera sliding 0.04 per frame and turning). Each cache is below 1 spp path tracing at every
/// seed's mean over those frames, by the one-sided 95% Student-t bound of the per-seed
/// differences (seeds 3, 4, 5).
#[test]
fn moving_camera_keeps_the_caches_near_the_per_frame_references() {
    let (w, h) = (common::W, common::H);
    let mut scene = common::room_scene();
    let mut sg = SceneGpu::new(
        gpu(),
        &scene,
        PathTracerSettings { width: w, height: h, max_depth: 3, rr_start_depth: 3 },
    )
    .expect("scene");
    let mut tracer = PathTracer::new(gpu(), &sg).expect("path tracer");
    let image = |rgba: &[[f32; 4]]| {
        metrics::Image::new(w, h, rgba.iter().map(|p| [p[0], p[1], p[2]]).collect())
    };
    let flip = |reference: &metrics::Image, rgba: &[[f32; 4]]| {
        metrics::flip_hdr(reference, &image(rgba), metrics::DEFAULT_PPD).mean
    };
    let camera = scene.camera;
    let move_camera = |scene: &mut SceneDesc, f: u32| {
        scene.camera.position = camera.position + Vec3::new(0.04 * f as f32, 0.0, 0.0);
        scene.camera.target = camera.target + Vec3::new(0.1 * f as f32, 0.0, 0.0);
    };
    let checkpoints = [5u32, 8, 11];
    let mut references: Vec<metrics::Image> = vec![];
    const METHODS: [&str; 5] =
        ["pt_1spp", "ssc_adaptive", "ssc_adaptive_taa", "hash_cache", "hash_cache_taa"];
    let mut per_seed: Vec<[f64; 5]> = vec![];
    for seed in [3u64, 4, 5] {
        let mut ssc =
            SampleCache::new(gpu(), &sg, SampleCacheSettings::default()).expect("sample cache");
        let mut ssc_taa = (
            SampleCache::new(gpu(), &sg, SampleCacheSettings { taa: true, ..Default::default() })
                .expect("sample cache"),
            Taa::new(gpu(), &sg, TaaSettings::default()).expect("taa"),
        );
        let mut hc = HashCache::new(gpu(), &sg, HashCacheSettings::default()).expect("hash cache");
        let mut hc_taa = (
            HashCache::new(gpu(), &sg, HashCacheSettings { taa: true, ..Default::default() })
                .expect("hash cache"),
            Taa::new(gpu(), &sg, TaaSettings::default()).expect("taa"),
        );
        // Frame 0 twice: no motion into the first frame.
        move_camera(&mut scene, 0);
        sg.update(gpu(), &scene);
        let mut sum = [0.0; 5];
        for f in 0..=checkpoints[2] {
            move_camera(&mut scene, f);
            sg.update(gpu(), &scene);
            let images = [
                tracer.render(gpu(), &sg, 1, seed, f).expect("1 spp").radiance,
                ssc.render(gpu(), &sg, seed, f).expect("ssc").radiance,
                {
                    ssc_taa.0.render(gpu(), &sg, seed, f).expect("ssc");
                    ssc_taa.0.resolve_taa(gpu(), &mut ssc_taa.1).expect("ssc taa").radiance
                },
                hc.render(gpu(), &sg, &scene.camera, seed, f, None).expect("hash cache").radiance,
                hc_taa
                    .0
                    .render(gpu(), &sg, &scene.camera, seed, f, Some(&mut hc_taa.1))
                    .expect("hash cache taa")
                    .radiance,
            ];
            let Some(k) = checkpoints.iter().position(|&c| c == f) else { continue };
            if references.len() == k {
                references.push(image(
                    &tracer.render(gpu(), &sg, 256, 1000, f).expect("reference").radiance,
                ));
            }
            for (m, img) in images.iter().enumerate() {
                sum[m] += flip(&references[k], img) / checkpoints.len() as f64;
            }
        }
        per_seed.push(sum);
    }
    eprintln!(
        "mean FLIP vs per-frame 256 spp at frames {checkpoints:?}, {METHODS:?} per seed: {per_seed:.4?}"
    );
    for m in 1..METHODS.len() {
        let d: Vec<f64> = per_seed.iter().map(|a| a[m] - a[0]).collect();
        let bound = common::upper_bound_of_mean(&d);
        eprintln!("{} - pt_1spp: {d:.4?}, bound {bound:.4}", METHODS[m]);
        assert!(
            bound < 0.0,
            "{} against 1 spp under motion: differences {d:?}, bound {bound}",
            METHODS[m]
        );
    }
}

/// The list passes (retrace_list_main, shade_main) dispatched indirectly with
/// the workgroup counts the GPU wrote (`list_dispatch`'s twin, checked here against the lists'
/// lengths) give the same image, counters and cached samples, bit for bit, as the direct dispatch over
/// N · pixels threads: the lists and each entry's work do not depend on the launch.
#[test]
fn indirect_list_dispatch_matches_the_direct_one() {
    let mut scene = scene(oblique(), true);
    for shading in [ShadingMode::Uniform, ShadingMode::Adaptive] {
        let settings = SampleCacheSettings {
            shading,
            shading_rate: if shading == ShadingMode::Adaptive { 0.5 } else { 1.0 },
            ..Default::default()
        };
        let mut indirect = Rig::new(&scene, settings);
        let mut direct = Rig::new(&scene, settings);
        direct.cache.set_indirect(false);
        for f in 0..6 {
            // Sideways: disocclusions along the step keep the retrace list long.
            scene.camera.position.x = 0.03 * f as f32;
            let a = indirect.step(&scene);
            let b = direct.step(&scene);
            assert_eq!(a.radiance, b.radiance, "{shading:?} frame {f}: images differ");
            assert!(
                a.motion == b.motion && a.flags == b.flags,
                "{shading:?} frame {f}: motion or flags differ"
            );
            // As text: the importance bounds are NaN before adaptive shading has seen a sample.
            assert_eq!(format!("{:?}", a.stats), format!("{:?}", b.stats), "{shading:?} frame {f}");
            let s = &a.stats;
            // Frame 0 only creates samples: nothing to retrace yet.
            assert!(
                (f == 0 || s.retrace_listed > 0) && s.shaded > 0,
                "{shading:?} frame {f}: empty lists {s:?}"
            );
            assert_eq!(
                s.list_args,
                [list_dispatch(s.retrace_listed), list_dispatch(s.shaded)],
                "{shading:?} frame {f}"
            );
            // The occupied slots (free ones keep whatever they last held).
            let (x, y) = (indirect.state(), direct.state());
            assert_eq!(x.masks, y.masks, "{shading:?} frame {f}: masks differ");
            let pixels = x.masks.len();
            for p in 0..pixels {
                assert_eq!(
                    samples(&x, p, settings.slots, false),
                    samples(&y, p, settings.slots, false),
                    "{shading:?} frame {f} pixel {p}"
                );
            }
        }
    }
}

#[test]
fn list_dispatch_covers_every_entry_within_the_limit() {
    for count in
        [0u32, 1, 63, 64, 65, 1_000_000, 65_535 * 64, 65_535 * 64 + 1, 25_000_000, u32::MAX / 2]
    {
        let [x, y, z] = list_dispatch(count);
        let threads = x as u64 * y as u64 * LIST_WORKGROUP as u64;
        assert!(
            threads >= count as u64 && x <= MAX_GROUPS_X && y <= MAX_GROUPS_X && z == 1,
            "{count}: {x} x {y}"
        );
        // No whole row of workgroups past the end.
        assert!(
            count == 0 || threads - (count as u64) < x as u64 * LIST_WORKGROUP as u64,
            "{count}: {x} x {y}"
        );
    }
}
