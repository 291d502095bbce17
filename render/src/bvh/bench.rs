//! Traversal benchmark: rays/s of the WGSL CWBVH traversal against obvhs's CPU traversal on
//! all cores (rayon), on the same BVHs and the same rays, in one run; and of the WGSL BVH2
//! traversal of the same triangles on the same rays. Plus the procedural
//! meshes and rays it (and the tests) use.

use std::time::{Duration, Instant};

use glam::{Vec2, Vec3};
use rayon::prelude::*;

use super::ray_order::sort_for_coherence;
use super::{
    Bvh2Geometry, Bvh2Traversal, BvhError, RayBatch, RayQuery, SceneGeometry, SplitMix64, TraceKind,
};
use crate::gpu::Gpu;
use crate::scene::{Mesh, SceneDesc};

/// Minimum wall time of each timed side; repetitions are added until it is reached.
const MIN_TIMED: Duration = Duration::from_millis(500);

/// Rounds of the WGSL-against-obvhs measurement: each times the WGSL traversal and then obvhs on
/// the same rays, so that each round's ratio compares two timings taken under the same load.
pub const PAIRED_ROUNDS: usize = 5;

#[derive(Clone, Debug)]
pub struct TraversalBench {
    pub adapter: String,
    pub triangles: u64,
    pub instances: u32,
    /// Entries of the WGSL traversal's stack, sized for the scene's BVH
    /// ([`RayBatch::stack_entries`]).
    pub stack_entries: u32,
    pub rays: u32,
    /// Building every BLAS and the TLAS on the CPU, plus the upload.
    pub build_seconds: f64,
    /// Closest-hit rays per second of the WGSL traversal, dispatch to completion (the rays are
    /// already on the GPU; no readback in the timing): the median of [`PAIRED_ROUNDS`] rounds.
    pub gpu_rays_per_second: f64,
    /// Closest-hit rays per second of obvhs's traversal on `cpu_threads` threads: the median of
    /// the same rounds, each timed right after the round's WGSL timing.
    pub cpu_rays_per_second: f64,
    /// WGSL over obvhs in each round, in round order (the machine's speed drifts between rounds;
    /// within one it barely does).
    pub paired_ratios: Vec<f64>,
    /// The same rays in coherence order (`ray_order::sort_for_coherence`, sorted on the CPU and
    /// not timed): WGSL and obvhs rays per second.
    pub gpu_sorted_rays_per_second: f64,
    pub cpu_sorted_rays_per_second: f64,
    /// The same random rays through obvhs's binary BVHs of the same triangles (`Bvh2Geometry`,
    /// `bvh2_traversal.wgsl`), timed right after the CWBVH traversal.
    pub gpu_bvh2_rays_per_second: f64,
    /// obvhs's own traversal of those BVH2s (`SceneBvh2`) on `cpu_threads` threads.
    pub cpu_bvh2_rays_per_second: f64,
    /// Building the BVH2s on the CPU, plus the upload.
    pub bvh2_build_seconds: f64,
    /// Fraction of rays where the BVH2 traversal and the CPU report the same instance and primitive.
    pub bvh2_agreement: f64,
    pub cpu_threads: usize,
    /// Fraction of rays that hit something.
    pub hit_fraction: f64,
    /// Fraction of rays where GPU and CPU report the same instance and primitive.
    pub agreement: f64,
}

impl std::fmt::Display for TraversalBench {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(
            f,
            "{} triangles, {} instances, {} rays: GPU {:.3} Mrays/s ({}), CPU {:.3} Mrays/s ({} threads), sorted GPU {:.3} CPU {:.3}, GPU BVH2 {:.3}, hits {:.1}%, GPU=CPU {:.2}%, BVH2=CPU {:.2}%, build {:.3} s",
            self.triangles,
            self.instances,
            self.rays,
            self.gpu_rays_per_second / 1e6,
            self.adapter,
            self.cpu_rays_per_second / 1e6,
            self.cpu_threads,
            self.gpu_sorted_rays_per_second / 1e6,
            self.cpu_sorted_rays_per_second / 1e6,
            self.gpu_bvh2_rays_per_second / 1e6,
            100.0 * self.hit_fraction,
            100.0 * self.agreement,
            100.0 * self.bvh2_agreement,
            self.build_seconds
        )
    }
}

/// Measures closest-hit traversal of `rays` random rays (origins inside the scene bounds,
/// uniform directions; seeded) on the GPU and on the CPU, after one warm-up run each.
pub fn traversal_benchmark(
    gpu: &Gpu,
    scene: &SceneDesc,
    rays: u32,
    seed: u64,
) -> Result<TraversalBench, BvhError> {
    let start = Instant::now();
    let geometry = SceneGeometry::new(gpu, scene)?;
    gpu.device
        .poll(wgpu::PollType::wait_indefinitely())
        .map_err(|e| BvhError::Readback { what: "scene upload".into(), reason: e.to_string() })?;
    let build_seconds = start.elapsed().as_secs_f64();
    let queries = random_rays(geometry.bounds(), rays as usize, 1e30, seed);

    let batch = RayBatch::new(gpu, &geometry);
    let buffers = batch.upload(gpu, &queries)?;
    batch.dispatch(gpu, &geometry, &buffers, TraceKind::Closest)?; // warm-up (pipeline compile, caches)
    let gpu_hits = batch.read_closest(gpu, &buffers)?;

    let start = Instant::now();
    let bvh2 = Bvh2Geometry::new(gpu, scene, &geometry)?;
    gpu.device
        .poll(wgpu::PollType::wait_indefinitely())
        .map_err(|e| BvhError::Readback { what: "BVH2 upload".into(), reason: e.to_string() })?;
    let bvh2_build_seconds = start.elapsed().as_secs_f64();
    let traversal = Bvh2Traversal { geometry: &geometry, bvh2: &bvh2 };
    let bvh2_batch = RayBatch::new_bvh2(gpu, &traversal);
    bvh2_batch.dispatch(gpu, &traversal, &buffers, TraceKind::Closest)?; // warm-up
    let (reps, elapsed) = repeat_until(MIN_TIMED, || {
        bvh2_batch.dispatch(gpu, &traversal, &buffers, TraceKind::Closest)
    })?;
    let gpu_bvh2_rays_per_second = (reps as f64 * rays as f64) / elapsed.as_secs_f64();
    let bvh2_hits = bvh2_batch.read_closest(gpu, &buffers)?;
    let (reps, elapsed) = repeat_until(MIN_TIMED, || {
        std::hint::black_box(
            queries
                .par_iter()
                .map(|r| bvh2.cpu().trace_closest(r.origin, r.direction, r.t_max))
                .collect::<Vec<_>>(),
        );
        Ok(())
    })?;
    let cpu_bvh2_rays_per_second = (reps as f64 * rays as f64) / elapsed.as_secs_f64();

    let cpu = geometry.cpu();
    let trace_all = || {
        queries
            .par_iter()
            .map(|r| cpu.trace_closest(r.origin, r.direction, r.t_max))
            .collect::<Vec<_>>()
    };
    let cpu_hits = trace_all(); // warm-up
    let (mut gpu_rates, mut cpu_rates, mut paired_ratios) = (Vec::new(), Vec::new(), Vec::new());
    for _ in 0..PAIRED_ROUNDS {
        let (reps, elapsed) = repeat_until(MIN_TIMED, || {
            batch.dispatch(gpu, &geometry, &buffers, TraceKind::Closest)
        })?;
        let gpu_rate = (reps as f64 * rays as f64) / elapsed.as_secs_f64();
        let (reps, elapsed) = repeat_until(MIN_TIMED, || {
            std::hint::black_box(trace_all());
            Ok(())
        })?;
        let cpu_rate = (reps as f64 * rays as f64) / elapsed.as_secs_f64();
        gpu_rates.push(gpu_rate);
        cpu_rates.push(cpu_rate);
        paired_ratios.push(gpu_rate / cpu_rate);
    }
    let (gpu_rays_per_second, cpu_rays_per_second) = (median(&gpu_rates), median(&cpu_rates));

    let sorted = sort_for_coherence(geometry.bounds(), &queries);
    let sorted_buffers = batch.upload(gpu, &sorted)?;
    batch.dispatch(gpu, &geometry, &sorted_buffers, TraceKind::Closest)?;
    let (reps, elapsed) = repeat_until(MIN_TIMED, || {
        batch.dispatch(gpu, &geometry, &sorted_buffers, TraceKind::Closest)
    })?;
    let gpu_sorted_rays_per_second = (reps as f64 * rays as f64) / elapsed.as_secs_f64();
    let (reps, elapsed) = repeat_until(MIN_TIMED, || {
        std::hint::black_box(
            sorted
                .par_iter()
                .map(|r| cpu.trace_closest(r.origin, r.direction, r.t_max))
                .collect::<Vec<_>>(),
        );
        Ok(())
    })?;
    let cpu_sorted_rays_per_second = (reps as f64 * rays as f64) / elapsed.as_secs_f64();

    let n = queries.len().max(1) as f64;
    let hit_fraction = cpu_hits.iter().filter(|h| h.is_hit()).count() as f64 / n;
    let agree = |hits: &[super::Hit]| {
        hits.iter()
            .zip(&cpu_hits)
            .filter(|(g, c)| g.instance == c.instance && g.primitive == c.primitive)
            .count() as f64
            / n
    };
    let (agreement, bvh2_agreement) = (agree(&gpu_hits), agree(&bvh2_hits));
    Ok(TraversalBench {
        adapter: gpu.summary.name.clone(),
        triangles: scene
            .instances
            .iter()
            .map(|i| scene.meshes[i.mesh as usize].indices.len() as u64)
            .sum(),
        instances: scene.instances.len() as u32,
        stack_entries: batch.stack_entries(),
        rays,
        build_seconds,
        gpu_rays_per_second,
        cpu_rays_per_second,
        paired_ratios,
        gpu_sorted_rays_per_second,
        cpu_sorted_rays_per_second,
        gpu_bvh2_rays_per_second,
        cpu_bvh2_rays_per_second,
        bvh2_build_seconds,
        bvh2_agreement,
        cpu_threads: rayon::current_num_threads(),
        hit_fraction,
        agreement,
    })
}

/// The median (the mean of the middle two for an even count).
pub fn median(values: &[f64]) -> f64 {
    let mut v = values.to_vec();
    v.sort_by(f64::total_cmp);
    let n = v.len();
    if n == 0 {
        return f64::NAN;
    }
    if n % 2 == 1 { v[n / 2] } else { 0.5 * (v[n / 2 - 1] + v[n / 2]) }
}

fn repeat_until(
    min: Duration,
    mut f: impl FnMut() -> Result<(), BvhError>,
) -> Result<(u32, Duration), BvhError> {
    let start = Instant::now();
    let mut reps = 0;
    while reps == 0 || start.elapsed() < min {
        f()?;
        reps += 1;
    }
    Ok((reps, start.elapsed()))
}

/// `count` rays with origins uniform in the box `bounds` grown by 10% of its diagonal, uniform
/// directions (unit length) and the given `t_max`; the same seed gives the same rays.
pub fn random_rays(bounds: (Vec3, Vec3), count: usize, t_max: f32, seed: u64) -> Vec<RayQuery> {
    let mut rng = SplitMix64::new(seed);
    let margin = Vec3::splat(0.1 * (bounds.1 - bounds.0).length().max(1e-3));
    let (lo, hi) = (bounds.0 - margin, bounds.1 + margin);
    (0..count)
        .map(|_| {
            let origin =
                Vec3::new(rng.range(lo.x, hi.x), rng.range(lo.y, hi.y), rng.range(lo.z, hi.z));
            RayQuery { origin, direction: rng.unit_vector(), t_max }
        })
        .collect()
}

/// A unit sphere with a seeded bumpy displacement (a few random sinusoids along the normal),
/// tessellated as a latitude-longitude grid with at least `min_triangles` triangles. Has smooth
/// normals and uvs. `displaced_sphere(100_000, seed)` is the benchmark's 100k-triangle mesh.
pub fn displaced_sphere(min_triangles: u32, seed: u64) -> Mesh {
    // 2 triangles per grid cell except one per cell in the two polar rows; slices = 2 * stacks.
    let mut stacks = 2u32;
    while 2 * (2 * stacks) * stacks - 2 * (2 * stacks) < min_triangles {
        stacks += 1;
    }
    let slices = 2 * stacks;
    let mut rng = SplitMix64::new(seed);
    let waves: Vec<(Vec3, f32, f32)> = (0..6)
        .map(|_| (rng.unit_vector(), rng.range(3.0, 12.0), rng.range(0.0, std::f32::consts::TAU)))
        .collect();
    let radius = |d: Vec3| {
        1.0 + waves.iter().map(|&(k, f, phase)| 0.02 * (f * k.dot(d) + phase).sin()).sum::<f32>()
    };

    let mut positions = Vec::new();
    let mut uvs = Vec::new();
    for i in 0..=stacks {
        let theta = std::f32::consts::PI * i as f32 / stacks as f32;
        for j in 0..=slices {
            let phi = std::f32::consts::TAU * j as f32 / slices as f32;
            let d = Vec3::new(theta.sin() * phi.cos(), theta.cos(), theta.sin() * phi.sin());
            positions.push(d * radius(d));
            uvs.push(Vec2::new(j as f32 / slices as f32, i as f32 / stacks as f32));
        }
    }
    let at = |i: u32, j: u32| i * (slices + 1) + j;
    let mut indices = Vec::new();
    for i in 0..stacks {
        for j in 0..slices {
            let (a, b, c, d) = (at(i, j), at(i + 1, j), at(i + 1, j + 1), at(i, j + 1));
            // Counter-clockwise seen from outside; in the polar rows one triangle of the cell
            // would be degenerate (a = d at the north pole, b = c at the south pole).
            if i != stacks - 1 {
                indices.push([a, c, b]);
            }
            if i != 0 {
                indices.push([a, d, c]);
            }
        }
    }
    let mut normals = vec![Vec3::ZERO; positions.len()];
    for t in &indices {
        let [a, b, c] = t.map(|i| positions[i as usize]);
        let n = (b - a).cross(c - a);
        for &i in t {
            normals[i as usize] += n;
        }
    }
    for n in &mut normals {
        *n = n.normalize_or(Vec3::Y);
    }
    Mesh {
        name: format!("displaced sphere ({} triangles)", indices.len()),
        positions,
        normals,
        uvs,
        indices,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn displaced_sphere_has_the_triangles_asked_and_faces_outwards() {
        let m = displaced_sphere(100_000, 3);
        assert!(m.indices.len() >= 100_000 && m.indices.len() < 105_000, "{}", m.indices.len());
        let mut outward = 0;
        for t in &m.indices {
            let [a, b, c] = t.map(|i| m.positions[i as usize]);
            if (b - a).cross(c - a).dot(a + b + c) > 0.0 {
                outward += 1;
            }
        }
        assert!(
            outward as f64 > 0.999 * m.indices.len() as f64,
            "{outward} of {}",
            m.indices.len()
        );
        assert_eq!(m.positions, displaced_sphere(100_000, 3).positions, "deterministic");
    }

    #[test]
    fn median_of_odd_and_even_counts() {
        assert_eq!(median(&[3.0, 1.0, 2.0]), 2.0);
        assert_eq!(median(&[4.0, 1.0, 3.0, 2.0]), 2.5);
        assert!(median(&[]).is_nan());
    }
}
