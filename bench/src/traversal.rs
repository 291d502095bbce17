//! Traversal benchmark: rays/s of the WGSL CWBVH traversal against obvhs's CPU traversal on
//! all cores (rayon), on the same BVHs and the same rays, in one run; and of the WGSL BVH2
//! traversal of the same triangles on the same rays.

use std::time::{Duration, Instant};

use rayon::prelude::*;
use render::bvh::{BvhError, Hit, RayBatch, SceneGeometry, TraceKind, random_rays};
use render::gpu::Gpu;
use render::scene::SceneDesc;

use crate::bvh2_batch::Bvh2Traversal;
use crate::bvh2_geometry::Bvh2Geometry;
use crate::ray_order::sort_for_coherence;

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
    let bvh2_batch = traversal.batch(gpu);
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
    let agree = |hits: &[Hit]| {
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

/// The lowest and the highest value (the spread of paired rounds).
pub fn range(values: &[f64]) -> (f64, f64) {
    values.iter().fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), &v| (lo.min(v), hi.max(v)))
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

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn median_of_odd_and_even_counts() {
        assert_eq!(median(&[3.0, 1.0, 2.0]), 2.0);
        assert_eq!(median(&[4.0, 1.0, 3.0, 2.0]), 2.5);
        assert!(median(&[]).is_nan());
    }
}
