//! Path tracing terminated into a hashed radiance cache by variance trading
//! (`cache`, ../shared/seeds/variance-trading-termination.txt). The methods whose
//! settings have one [`TerminationSettings::cache_key`] share one [`SharedTerminationCache`]
//! entity (their records are bit-identical, as the paper's rules share one propagation); each
//! method has its own tracer. Three systems: in Render the records' update once per cache
//! (`update`: propagation and fold, after the warm-up on the first frame) and each method's
//! image (`trace`: the tracer with the rule's decision), which reports the image, the pass
//! times and the mean path length (`path_length`, vertices per path counted on the GPU), with
//! the per-pixel path length as the image `path_length` (the paper's Fig. 11); in Learn the
//! insertion and vertex store once per cache (`store`). The cache's passes (tc_propagate,
//! tc_fold, tc_insert, tc_store) and their CPU time are reported by the cache's first method
//! (its owner) only; every method reports its own tc_trace. Propagation traces the frame's
//! scene from its camera and the fold feeds the image, so both stay before it.

use std::time::Instant;

use crate::TerminationCache;
use crate::TerminationTracer;
use crate::rule::TerminationRule;
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

/// One cache shared by the methods with its key: its passes run once a frame.
#[derive(Component)]
pub struct SharedTerminationCache {
    key: TerminationSettings,
    cache: TerminationCache,
    /// The first method of this cache: it offers the primary vertices and reports the
    /// cache's passes.
    owner: Entity,
    /// This frame's update times, from `update` to the owner's `trace`.
    updated: Option<Vec<PassTiming>>,
}

/// One termination method: its tracer over its cache.
#[derive(Component)]
pub struct TerminationState {
    cache: Entity,
    tracer: TerminationTracer,
}

pub struct Plugin;

impl MethodPlugin for Plugin {
    type Settings = TerminationSettings;
    const NAME: &'static str = "Termination";
    const STATISTICS: &'static [frame::method::Statistic] = crate::recorded::STATISTICS;
    const COMPUTATIONS: &'static [frame::method::DeclaredComputation] =
        crate::figures::COMPUTATIONS;
    const CHARTS: &'static [frame::method::MethodChart] = crate::recorded::CHARTS;

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
        settings.validate()?;
        let key = settings.cache_key();
        let existing = world
            .query::<(Entity, &SharedTerminationCache)>()
            .iter(world)
            .find(|(_, c)| c.key == key)
            .map(|(e, _)| e);
        let (cache, offers) = match existing {
            Some(e) => (e, false),
            None => {
                let (gpu, gpu_scene) =
                    (&world.resource::<GpuDevice>().0, &world.resource::<GpuScene>().0);
                // Checks the cache's buffers against the adapter's limits.
                let cache = TerminationCache::new(gpu, gpu_scene, *settings)?;
                let shared = SharedTerminationCache { key, cache, owner: entity, updated: None };
                (world.spawn(shared).id(), true)
            }
        };
        let tracer = {
            let gpu = &world.resource::<GpuDevice>().0;
            let shared = world.get::<SharedTerminationCache>(cache).expect("a cache entity");
            shared.cache.tracer(gpu, *settings, offers)?
        };
        world.entity_mut(entity).insert(TerminationState { cache, tracer });
        Ok(())
    }
}

/// The records the images read, once per cache: the warm-up on the first frame, then
/// propagation and fold. The CPU time is the owner's.
pub fn update(
    gpu: Res<GpuDevice>,
    gpu_scene: Res<GpuScene>,
    run: Res<Run>,
    clock: Res<FrameClock>,
    scene: Res<sim::ExtractedScene>,
    mut caches: Query<&mut SharedTerminationCache>,
    mut methods: Query<(&MethodInfo, &mut MethodFrame)>,
) -> Result<(), BevyError> {
    for mut shared in &mut caches {
        let start = Instant::now();
        let Ok((info, mut frame)) = methods.get_mut(shared.owner) else {
            return Err(method_failed("termination", clock.global, "a cache without its owner"));
        };
        let updated = shared
            .cache
            .update(&gpu.0, &gpu_scene.0, &scene.scene.camera, run.scenario.seed, clock.global)
            .map_err(|e| method_failed(&info.label, clock.global, e))?;
        shared.updated = Some(updated);
        frame.add_cpu(start);
    }
    Ok(())
}

/// The frame's image (one path per pixel, the rule deciding at every vertex) and its output.
/// The owner's output starts with the cache's update times.
pub fn trace(
    gpu: Res<GpuDevice>,
    gpu_scene: Res<GpuScene>,
    clock: Res<FrameClock>,
    mut caches: Query<&mut SharedTerminationCache>,
    mut methods: Query<(Entity, &TerminationState, &MethodInfo, &mut MethodFrame)>,
) -> Result<(), BevyError> {
    for (entity, state, info, mut frame) in &mut methods {
        let start = Instant::now();
        let mut shared =
            caches.get_mut(state.cache).map_err(|e| method_failed(&info.label, clock.global, e))?;
        let updated =
            if shared.owner == entity { shared.updated.take() } else { None }.unwrap_or_default();
        let out = shared
            .cache
            .trace_with(&gpu.0, &gpu_scene.0, &state.tracer, updated)
            .map_err(|e| method_failed(&info.label, clock.global, e))?;
        let s = out.stats;
        let settings = state.tracer.settings();
        let unit = shared.cache.radiance_unit(&settings);
        let mut stats: Vec<(String, f64)> = vec![
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
            ("cache_bytes".into(), shared.cache.cache_bytes() as f64),
            // The unit of an absolute threshold (t · unit²): stated, or the cache's mean.
            ("radiance_unit".into(), unit),
            ("cache_unknown_vertices".into(), s.unknown as f64),
            ("cache_propagated_vertices".into(), s.propagated as f64),
            // Propagated vertices with a sample that read no filled record: left out of
            // filled records' moments (their share measures what that leaves out).
            ("cache_incomplete_vertices".into(), s.incomplete as f64),
            ("cache_insert_failures".into(), s.insert_failures as f64),
        ];
        if let TerminationRule::VarianceBounding { t, relative: false } = settings.rule
            && t * unit * unit > 0.0
        {
            // Fig. 7's bound on the path variance (luminance²), which the image variance is
            // judged against (`flicker reproduce`'s variance_over_bound). As log10: frames.csv
            // keeps 6 decimals, and bounds are 1e-6 and below.
            stats.push(("variance_bound_log10".into(), (t * unit * unit).log10()));
        }
        frame.output = Some(MethodOutput {
            stats,
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

/// After the images, once per cache: the frame's candidates become the stored vertices the
/// next frame propagates; the pass times join the owner's output, the insertion failures every
/// method's.
pub fn store(
    gpu: Res<GpuDevice>,
    gpu_scene: Res<GpuScene>,
    clock: Res<FrameClock>,
    mut caches: Query<(Entity, &mut SharedTerminationCache)>,
    mut methods: Query<(Entity, &TerminationState, &MethodInfo, &mut MethodFrame)>,
) -> Result<(), BevyError> {
    for (cache, mut shared) in &mut caches {
        let start = Instant::now();
        let owner = shared.owner;
        let fail = |e| method_failed("termination", clock.global, e);
        let timings = shared.cache.store(&gpu.0, &gpu_scene.0).map_err(fail)?;
        // Insertions are settled after the image: their failures are counted by now.
        let failures = shared.cache.read_counters(&gpu.0).map_err(fail)?.insert_failures;
        for (entity, state, info, mut frame) in &mut methods {
            if state.cache != cache {
                continue;
            }
            let Some(output) = frame.output.as_mut() else {
                return Err(method_failed(
                    &info.label,
                    clock.global,
                    "the vertex store ran before the frame's image",
                ));
            };
            if entity == owner {
                output.add_timed(&timings);
            }
            if let Some(stat) =
                output.stats.iter_mut().find(|(name, _)| name == "cache_insert_failures")
            {
                stat.1 = failures as f64;
            }
            if entity == owner {
                frame.add_cpu(start);
            }
        }
    }
    Ok(())
}
