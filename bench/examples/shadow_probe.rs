//! Why the wavefront's shadow kernel (any hit, bounded t) took longer than its extend kernel
//! (closest hit, unbounded t) in every `flicker bench` run: the two kinds of ray traced alone,
//! through the ray batch, on the bench's Lambertian Cornell box, and the wavefront's kernels
//! timed one by one.
//!
//! Surface points are the closest hits of rays from random points inside the room; from each,
//! a "bounce" ray (cosine-distributed about the side the point was seen from, t unbounded) and a
//! "shadow" ray (to a uniform point on the emissive quad, t = 0.999 of its distance, as
//! wavefront.wgsl's emitter sample). Each set is traced both ways (closest and any hit) on the
//! GPU and by obvhs on the CPU, so that the kind of ray and the kind of query are told apart.
//! `cargo run --release -p bench --example shadow_probe [-- RAYS [REPEATS]]`
use std::time::{Duration, Instant};

use glam::Vec3;
use rayon::prelude::*;
use render::bvh::{RayBatch, RayQuery, SceneGeometry, SplitMix64, TraceKind};
use render::gpu::Gpu;
use render::path_tracer::{PathTracer, PathTracerSettings};
use render::scene::SceneDesc;
use render::scene_gpu::SceneGpu;

const MIN_TIMED: Duration = Duration::from_millis(400);

/// wavefront.wgsl's offset_origin.
fn offset_origin(p: Vec3, ng: Vec3, dir: Vec3) -> Vec3 {
    let scale = 1.0e-4 * (1.0 + p.abs().max_element());
    p + ng * if dir.dot(ng) >= 0.0 { scale } else { -scale }
}

/// World triangles of the emissive instances.
fn emitters(scene: &SceneDesc) -> Vec<[Vec3; 3]> {
    let mut out = Vec::new();
    for inst in &scene.instances {
        if scene.materials[inst.material as usize].emission.max_element() <= 0.0 {
            continue;
        }
        let mesh = &scene.meshes[inst.mesh as usize];
        for tri in &mesh.indices {
            out.push(tri.map(|i| inst.transform.transform_point3(mesh.positions[i as usize])));
        }
    }
    out
}

struct RaySets {
    bounce: Vec<RayQuery>,
    shadow: Vec<RayQuery>,
}

fn ray_sets(gpu: &Gpu, geometry: &SceneGeometry, scene: &SceneDesc, count: usize) -> RaySets {
    let (lo, hi) = geometry.bounds();
    let inset = 0.02 * (hi - lo);
    let mut rng = SplitMix64::new(7);
    let primary: Vec<RayQuery> = (0..count)
        .map(|_| {
            let o = Vec3::new(
                rng.range(lo.x + inset.x, hi.x - inset.x),
                rng.range(lo.y + inset.y, hi.y - inset.y),
                rng.range(lo.z + inset.z, hi.z - inset.z),
            );
            RayQuery { origin: o, direction: rng.unit_vector(), t_max: 1e30 }
        })
        .collect();
    let batch = RayBatch::new(gpu, geometry);
    let buffers = batch.upload(gpu, &primary).unwrap();
    batch.dispatch(gpu, geometry, &buffers, TraceKind::Closest).unwrap();
    let hits = batch.read_closest(gpu, &buffers).unwrap();
    batch.dispatch(gpu, geometry, &buffers, TraceKind::SurfacePoints).unwrap();
    let points = batch.read_surface_points(gpu, &buffers).unwrap();
    let lights = emitters(scene);
    let (mut bounce, mut shadow) = (Vec::new(), Vec::new());
    for ((ray, hit), sp) in primary.iter().zip(&hits).zip(&points) {
        if !hit.is_hit() {
            continue;
        }
        let p = sp.position;
        let ng = if sp.geometric_normal.dot(ray.direction) <= 0.0 {
            sp.geometric_normal
        } else {
            -sp.geometric_normal
        };
        // Cosine-distributed about ng.
        let (u1, u2) = (rng.next_f32(), rng.next_f32());
        let (r, phi) = (u1.sqrt(), std::f32::consts::TAU * u2);
        let (t, b) = ng.any_orthonormal_pair();
        let wi = (t * (r * phi.cos()) + b * (r * phi.sin()) + ng * (1.0 - u1).max(0.0).sqrt())
            .normalize();
        bounce.push(RayQuery { origin: offset_origin(p, ng, wi), direction: wi, t_max: 1e30 });
        if lights.is_empty() {
            continue;
        }
        let tri = lights[(rng.next_f32() * lights.len() as f32) as usize % lights.len()];
        let (mut a, mut c) = (rng.next_f32(), rng.next_f32());
        if a + c > 1.0 {
            (a, c) = (1.0 - a, 1.0 - c);
        }
        let x = tri[0] + a * (tri[1] - tri[0]) + c * (tri[2] - tri[0]);
        let d = x - p;
        let dist = d.length();
        let wi = d / dist;
        let light_n = (tri[1] - tri[0]).cross(tri[2] - tri[0]).normalize();
        if wi.dot(ng) <= 0.0 || -light_n.dot(wi) <= 0.0 {
            continue;
        }
        shadow.push(RayQuery {
            origin: offset_origin(p, ng, wi),
            direction: wi,
            t_max: dist * (1.0 - 1.0e-3),
        });
    }
    RaySets { bounce, shadow }
}

/// Instance entries and triangle tests per ray of obvhs's traversal of the same BVHs (closest or
/// any hit), and the TLAS's leaves: how many instances each holds.
/// With `boxed`, an instance is entered only if the ray meets its padded world box
/// (`sg_box_entered`).
fn counts(cpu: &render::bvh::SceneBvh, rays: &[RayQuery], any: bool, boxed: bool) -> (f64, f64) {
    use render::bvh::{WatertightRay, intersect_triangle, obvhs_ray};
    let (mut entries, mut tests) = (0u64, 0u64);
    for r in rays {
        let mut best = r.t_max;
        let enter =
            |instance: u32, t_max: f32, entries: &mut u64, tests: &mut u64| -> Option<f32> {
                let inst = &cpu.instances[instance as usize];
                if boxed {
                    let b = render::bvh::world_bounds(
                        &inst.object_to_world,
                        &cpu.blas[inst.mesh as usize].bounds,
                    );
                    let (lo, hi) = render::bvh::padded_leaf_box(&b);
                    let (lo, hi) = (Vec3::from(lo), Vec3::from(hi));
                    let inv = r.direction.recip();
                    let a = (lo - r.origin) * inv;
                    let c = (hi - r.origin) * inv;
                    let t0 = a.min(c).max_element().max(0.0);
                    let t1 = a.max(c).min_element().min(t_max);
                    if t0 > t1 * 1.0000004 {
                        return None;
                    }
                }
                *entries += 1;
                let o = inst.world_to_object.transform_point3(r.origin);
                let d = inst.world_to_object.transform_vector3(r.direction);
                let blas = &cpu.blas[inst.mesh as usize];
                let tri_ray = WatertightRay::new(o, d);
                let mut found = None;
                let mut hit = obvhs::ray::RayHit::none();
                blas.bvh.ray_traverse(obvhs_ray(o, d, t_max), &mut hit, |ray, slot| {
                    *tests += 1;
                    let [a, b, c] = blas.triangles[slot];
                    match intersect_triangle(&tri_ray, a, b, c, ray.tmax) {
                        Some((t, _)) => {
                            found = Some(t);
                            if any { 0.0 } else { t }
                        }
                        None => f32::INFINITY,
                    }
                });
                found
            };
        if any {
            cpu.tlas.bvh.ray_traverse_miss(obvhs_ray(r.origin, r.direction, r.t_max), |_, slot| {
                let instance = cpu.tlas.bvh.primitive_indices[slot];
                enter(instance, r.t_max, &mut entries, &mut tests).map_or(f32::INFINITY, |_| 0.0)
            });
        } else {
            let mut hit = obvhs::ray::RayHit::none();
            cpu.tlas.bvh.ray_traverse(
                obvhs_ray(r.origin, r.direction, r.t_max),
                &mut hit,
                |ray, slot| {
                    let instance = cpu.tlas.bvh.primitive_indices[slot];
                    match enter(instance, ray.tmax.min(best), &mut entries, &mut tests) {
                        Some(t) => {
                            best = t;
                            t
                        }
                        None => f32::INFINITY,
                    }
                },
            );
        }
    }
    let n = rays.len().max(1) as f64;
    (entries as f64 / n, tests as f64 / n)
}

fn tlas_leaves(cpu: &render::bvh::SceneBvh) -> String {
    let mut out = Vec::new();
    for (n, node) in cpu.tlas.bvh.nodes.iter().enumerate() {
        for ch in 0..8 {
            if node.is_child_empty(ch) {
                continue;
            }
            if node.is_leaf(ch) {
                let (first, count) = node.child_primitives(ch);
                let ids: Vec<u32> = (first..first + count)
                    .map(|k| cpu.tlas.bvh.primitive_indices[k as usize])
                    .collect();
                out.push(format!("node {n} leaf {ids:?}"));
            } else {
                out.push(format!("node {n} inner"));
            }
        }
    }
    out.join(", ")
}

fn rate(count: usize, mut f: impl FnMut()) -> f64 {
    f();
    let start = Instant::now();
    let mut reps = 0;
    while reps == 0 || start.elapsed() < MIN_TIMED {
        f();
        reps += 1;
    }
    reps as f64 * count as f64 / start.elapsed().as_secs_f64() / 1e6
}

fn main() -> anyhow::Result<()> {
    let args: Vec<String> = std::env::args().collect();
    let mode = args.get(1).cloned().unwrap_or_else(|| "all".into());
    let rays: usize = args.get(2).map(|s| s.parse()).transpose()?.unwrap_or(65_536);
    let repeats: usize = args.get(3).map(|s| s.parse()).transpose()?.unwrap_or(3);
    let gpu = Gpu::new()?;
    println!("Adapter: {}", gpu.summary);
    let scene = bench::mitsuba::lambertian_cornell_box((64, 64))?;
    if mode == "all" || mode == "cornell" {
        cornell_rays(&gpu, &scene, rays, repeats)?;
    }
    if mode == "all" || mode == "deep" {
        deep(&gpu, rays, repeats)?;
    }
    if mode == "all" || mode == "wavefront" {
        wavefront(&gpu, &scene, repeats)?;
    }
    Ok(())
}

/// The traversal bench's random rays (closest hit, unbounded) on its two deep scenes, GPU and
/// obvhs in paired rounds, and the GPU's any-hit rate on the same rays.
fn deep(gpu: &Gpu, rays: usize, repeats: usize) -> anyhow::Result<()> {
    let sphere = SceneDesc {
        meshes: vec![render::bvh::displaced_sphere(100_000, 1)],
        materials: vec![render::scene::Material::default()],
        instances: vec![render::scene::Instance {
            mesh: 0,
            material: 0,
            transform: glam::Mat4::IDENTITY,
        }],
        ..Default::default()
    };
    let scenes = [
        ("cornell_box", playback::scenario::builtin_scene("cornell_box", (64, 36))?),
        ("hairball", playback::scenario::builtin_scene("hairball", (64, 36))?),
        ("displaced sphere 100k", sphere),
    ];
    println!("\n| scene | round | GPU closest | CPU closest | GPU / CPU | GPU any | (M rays/s) |");
    println!("|---|---|---:|---:|---:|---:|---|");
    for (name, scene) in &scenes {
        let geometry = SceneGeometry::new(gpu, scene)?;
        let queries = render::bvh::random_rays(geometry.bounds(), rays, 1e30, 1);
        let batch = RayBatch::new(gpu, &geometry);
        let buffers = batch.upload(gpu, &queries)?;
        let cpu = geometry.cpu();
        for round in 0..repeats {
            let g = rate(queries.len(), || {
                batch.dispatch(gpu, &geometry, &buffers, TraceKind::Closest).unwrap()
            });
            let c = rate(queries.len(), || {
                std::hint::black_box(
                    queries
                        .par_iter()
                        .map(|r| cpu.trace_closest(r.origin, r.direction, r.t_max))
                        .collect::<Vec<_>>(),
                );
            });
            let a = rate(queries.len(), || {
                batch.dispatch(gpu, &geometry, &buffers, TraceKind::Any).unwrap()
            });
            println!("| {name} | {round} | {g:.3} | {c:.3} | {:.2} | {a:.3} | |", g / c);
        }
    }
    Ok(())
}

fn cornell_rays(gpu: &Gpu, scene: &SceneDesc, rays: usize, repeats: usize) -> anyhow::Result<()> {
    let geometry = SceneGeometry::new(gpu, scene)?;
    let sets = ray_sets(gpu, &geometry, scene, rays);
    let cpu = geometry.cpu();
    let batch = RayBatch::new(gpu, &geometry);
    println!(
        "{} bounce rays, {} shadow rays (occluded: {:.1}%), stack entries {}",
        sets.bounce.len(),
        sets.shadow.len(),
        100.0
            * sets.shadow.iter().filter(|r| cpu.trace_any(r.origin, r.direction, r.t_max)).count()
                as f64
            / sets.shadow.len().max(1) as f64,
        batch.stack_entries()
    );
    println!("TLAS: {}", tlas_leaves(cpu));
    for (name, set) in [("bounce", &sets.bounce), ("shadow", &sets.shadow)] {
        for boxed in [false, true] {
            let (ec, tc) = counts(cpu, set, false, boxed);
            let (ea, ta) = counts(cpu, set, true, boxed);
            println!(
                "{name}{}: obvhs closest: {ec:.2} instance entries, {tc:.2} triangle tests per ray; any: {ea:.2}, {ta:.2}",
                if boxed { ", instance boxes tested" } else { "" }
            );
        }
    }
    println!("\n| round | set | GPU closest | GPU any | CPU closest | CPU any | (M rays/s) |");
    println!("|---|---|---:|---:|---:|---:|---|");
    for round in 0..repeats {
        for (name, set) in [("bounce", &sets.bounce), ("shadow", &sets.shadow)] {
            let buffers = batch.upload(gpu, set)?;
            let g =
                |kind| rate(set.len(), || batch.dispatch(gpu, &geometry, &buffers, kind).unwrap());
            let (gc, ga) = (g(TraceKind::Closest), g(TraceKind::Any));
            let cc = rate(set.len(), || {
                std::hint::black_box(
                    set.par_iter()
                        .map(|r| cpu.trace_closest(r.origin, r.direction, r.t_max))
                        .collect::<Vec<_>>(),
                );
            });
            let ca = rate(set.len(), || {
                std::hint::black_box(
                    set.par_iter()
                        .map(|r| cpu.trace_any(r.origin, r.direction, r.t_max))
                        .collect::<Vec<_>>(),
                );
            });
            println!("| {round} | {name} | {gc:.3} | {ga:.3} | {cc:.3} | {ca:.3} | |");
        }
    }

    Ok(())
}

/// The wavefront's kernels, each submitted alone, as `flicker bench` times them.
fn wavefront(gpu: &Gpu, scene: &SceneDesc, repeats: usize) -> anyhow::Result<()> {
    let spp: u32 = 64;
    let settings = PathTracerSettings { width: 64, height: 64, max_depth: 1000, rr_start_depth: 3 };
    let mut gpu_scene = SceneGpu::new(gpu, scene, settings)?;
    let mut tracer = PathTracer::new(gpu, &gpu_scene)?;
    gpu_scene.update(gpu, scene);
    let wavefront = bench::wavefront::Wavefront::new(gpu, &gpu_scene)?;
    wavefront.render_reference(gpu, &gpu_scene, &tracer, 1, 1, 0)?;
    tracer.render_reference(gpu, &gpu_scene, 1, 1, 0, &mut |_, _| {})?;
    println!(
        "\n| round | megakernel | {} | (s, {spp} spp at 64x64) |",
        bench::wavefront::Kernel::ALL.map(|k| k.name()).join(" | ")
    );
    println!("|---|{}---|", "---:|".repeat(7));
    for round in 0..repeats {
        let start = Instant::now();
        tracer.render_reference(gpu, &gpu_scene, spp, 1, 0, &mut |_, _| {})?;
        let mega = start.elapsed().as_secs_f64();
        let mut times = bench::wavefront::KernelTimes::default();
        let image = wavefront
            .render_reference_per_kernel(gpu, &gpu_scene, &tracer, spp, 1, 0, &mut times)?;
        let mean: f64 = image.iter().map(|p| p[0] as f64 + p[1] as f64 + p[2] as f64).sum::<f64>()
            / image.len() as f64;
        println!(
            "| {round} | {mega:.3} | {} | mean {mean:.7} |",
            times.seconds.map(|s| format!("{s:.3}")).join(" | ")
        );
    }
    Ok(())
}
