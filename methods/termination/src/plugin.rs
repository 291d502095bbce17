//! Path tracing terminated into a hashed radiance cache by variance trading
//! (render::termination, ../shared/seeds/variance-trading-termination.txt). Three systems: in
//! Render the records' update (`update`: propagation and fold, after the warm-up on the first
//! frame) and the image (`trace`: the tracer with the rule's decision), which reports the image,
//! the pass times (tc_trace and tc_propagate separately) and the mean path length
//! (`path_length`, vertices per path counted on the GPU), with the per-pixel path length as the
//! image `path_length` (the paper's Fig. 11); in Learn the vertex store (`store`), whose time
//! joins the frame's. Propagation traces the frame's scene from its camera and the fold feeds
//! the image, so both stay before it.

use std::time::Instant;

use crate::TerminationCache;
use anyhow::Result;
use bevy_ecs::prelude::*;
use render::timing::PassTiming;

pub use crate::TerminationSettings;

use frame::{FrameClock, GpuDevice, GpuScene, MethodFrame, MethodInfo, Run, Stage, method_failed};
use frame::{MethodImage, MethodOutput, MethodPlugin};

/// `termination_vb_0.1`, `termination_mse_100`, ...
pub fn label(s: &TerminationSettings) -> String {
    format!("termination_{}", s.rule.label())
}

#[derive(Component)]
pub struct TerminationState {
    cache: TerminationCache,
    /// This frame's update times, from `update` to `trace`.
    updated: Option<Vec<PassTiming>>,
}

pub struct Plugin;

impl MethodPlugin for Plugin {
    type Settings = TerminationSettings;
    const NAME: &'static str = "Termination";

    fn label(settings: &TerminationSettings) -> String {
        label(settings)
    }

    fn spp(_settings: &TerminationSettings) -> f64 {
        1.0
    }

    fn temporal_window(_settings: &TerminationSettings) -> Option<f64> {
        None
    }

    fn add_systems(schedule: &mut Schedule) {
        schedule.add_systems((update, trace).chain().in_set(Stage::Render));
        schedule.add_systems(store.in_set(Stage::Learn));
    }

    fn spawn(world: &mut World, entity: Entity, settings: &TerminationSettings) -> Result<()> {
        let (gpu, gpu_scene) = (&world.resource::<GpuDevice>().0, &world.resource::<GpuScene>().0);
        // Validates the settings and checks the cache's buffers against the adapter's limits.
        let cache = TerminationCache::new(gpu, gpu_scene, *settings)?;
        world.entity_mut(entity).insert(TerminationState { cache, updated: None });
        Ok(())
    }
}

/// The records the image reads: the warm-up on the first frame, then propagation and fold.
pub fn update(
    gpu: Res<GpuDevice>,
    gpu_scene: Res<GpuScene>,
    run: Res<Run>,
    clock: Res<FrameClock>,
    scene: Res<sim::ExtractedScene>,
    mut methods: Query<(&mut TerminationState, &MethodInfo, &mut MethodFrame)>,
) -> Result<(), BevyError> {
    for (mut state, info, mut frame) in &mut methods {
        let start = Instant::now();
        let updated = state
            .cache
            .update(&gpu.0, &gpu_scene.0, &scene.scene.camera, run.scenario.seed, clock.global)
            .map_err(|e| method_failed(&info.label, clock.global, e))?;
        state.updated = Some(updated);
        frame.add_cpu(start);
    }
    Ok(())
}

/// The frame's image (one path per pixel, the rule deciding at every vertex) and its output.
pub fn trace(
    gpu: Res<GpuDevice>,
    gpu_scene: Res<GpuScene>,
    clock: Res<FrameClock>,
    mut methods: Query<(&mut TerminationState, &MethodInfo, &mut MethodFrame)>,
) -> Result<(), BevyError> {
    for (mut state, info, mut frame) in &mut methods {
        let start = Instant::now();
        let updated = state.updated.take().unwrap_or_default();
        let out = state
            .cache
            .trace(&gpu.0, &gpu_scene.0, updated)
            .map_err(|e| method_failed(&info.label, clock.global, e))?;
        let s = out.stats;
        frame.output = Some(MethodOutput {
            stats: vec![
                ("path_length".into(), out.mean_path_length),
                ("cache_records".into(), s.filled as f64),
                ("cache_mean".into(), out.cache.mean),
                ("cache_variance".into(), out.cache.variance),
                ("cache_bias2".into(), out.cache.bias2),
                ("cache_variance_p10".into(), out.cache.variance_quantiles[0]),
                ("cache_variance_p50".into(), out.cache.variance_quantiles[1]),
                ("cache_variance_p90".into(), out.cache.variance_quantiles[2]),
                ("cache_mean_p10".into(), out.cache.mean_quantiles[0]),
                ("cache_mean_p50".into(), out.cache.mean_quantiles[1]),
                ("cache_mean_p90".into(), out.cache.mean_quantiles[2]),
                ("cache_bytes".into(), state.cache.cache_bytes() as f64),
                ("cache_unknown_vertices".into(), s.unknown as f64),
                ("cache_propagated_vertices".into(), s.propagated as f64),
                // Propagated vertices with a sample that read no filled record: left out of
                // filled records' moments (their share measures what that leaves out).
                ("cache_incomplete_vertices".into(), s.incomplete as f64),
                ("cache_insert_failures".into(), s.insert_failures as f64),
            ],
            // The paper's Fig. 11: vertices of each pixel's path (grey value = path length; the
            // EXR holds the exact values).
            images: vec![MethodImage {
                name: "path_length".into(),
                pixels: out.path_length.iter().map(|&l| [l, l, l, 1.0]).collect(),
                hdr: true,
            }],
            ..MethodOutput::timed(out.radiance, out.motion, &out.timings, out.rays, out.shaded)
        });
        frame.add_cpu(start);
    }
    Ok(())
}

/// After the image: the frame's candidates become the stored vertices the next frame
/// propagates; the pass time joins the frame's output.
pub fn store(
    gpu: Res<GpuDevice>,
    gpu_scene: Res<GpuScene>,
    clock: Res<FrameClock>,
    mut methods: Query<(&mut TerminationState, &MethodInfo, &mut MethodFrame)>,
) -> Result<(), BevyError> {
    for (mut state, info, mut frame) in &mut methods {
        let start = Instant::now();
        let timings = state
            .cache
            .store(&gpu.0, &gpu_scene.0)
            .map_err(|e| method_failed(&info.label, clock.global, e))?;
        let Some(output) = frame.output.as_mut() else {
            return Err(method_failed(
                &info.label,
                clock.global,
                "the vertex store ran before the frame's image",
            ));
        };
        output.add_timed(&timings);
        // Insertions are settled after the image: their failures are counted by now.
        let failures = state
            .cache
            .read_counters(&gpu.0)
            .map_err(|e| method_failed(&info.label, clock.global, e))?
            .insert_failures;
        if let Some(stat) =
            output.stats.iter_mut().find(|(name, _)| name == "cache_insert_failures")
        {
            stat.1 = failures as f64;
        }
        frame.add_cpu(start);
    }
    Ok(())
}
