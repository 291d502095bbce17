//! World-space hash cache (the crate's `lib.rs`), optionally under TAA as the paper runs it. Two
//! systems, both in Render: the cache's upkeep (`update`: age = eviction, then lookups and
//! updates), then the image (`resolve`: the cache's colour, and TAA's resolve of it). Nothing of
//! the cache runs after the image: the image reads the cells this frame's update wrote, and the
//! eviction is stamped with the frame it starts.

use std::time::Instant;

use crate::{HashCache, HashCacheLookup};
use anyhow::Result;
use bevy_ecs::prelude::*;
use render::timing::PassTiming;
use taa::{Taa, TaaSettings};

pub use crate::HashCacheSettings;

use frame::{FrameClock, GpuDevice, GpuScene, MethodFrame, MethodInfo, Run, Stage, method_failed};
use frame::{MethodOutput, MethodPlugin, temporal_window};

/// `hash_cache` (the paper's first-hit lookup), `hash_cache_taa` (under TAA, as the paper runs
/// it), `hash_cache_secondary_hit`, `hash_cache_secondary_hit_taa`.
pub fn label(s: &HashCacheSettings) -> String {
    format!(
        "hash_cache{}{}",
        if s.lookup == HashCacheLookup::SecondaryHit { "_secondary_hit" } else { "" },
        if s.taa { "_taa" } else { "" }
    )
}

#[derive(Component)]
pub struct HashCacheState {
    cache: HashCache,
    taa: Option<Taa>,
    /// This frame's pass times and primary jitter, from `update` to `resolve`.
    updated: Option<(Vec<PassTiming>, [f32; 2])>,
}

pub struct Plugin;

impl MethodPlugin for Plugin {
    type Settings = HashCacheSettings;
    const NAME: &'static str = "HashCache";

    fn label(settings: &HashCacheSettings) -> String {
        label(settings)
    }

    fn spp(_settings: &HashCacheSettings) -> f64 {
        1.0
    }

    fn temporal_window(settings: &HashCacheSettings) -> Option<f64> {
        Some(taa::plugin::window_under_taa(
            temporal_window::exponential(1.0 / settings.max_samples as f64),
            settings.taa,
        ))
    }

    fn add_systems(schedule: &mut Schedule) {
        schedule.add_systems((update, resolve).chain().in_set(Stage::Render));
    }

    fn spawn(world: &mut World, entity: Entity, settings: &HashCacheSettings) -> Result<()> {
        settings.validate()?;
        let (gpu, gpu_scene) = (&world.resource::<GpuDevice>().0, &world.resource::<GpuScene>().0);
        let cache = HashCache::new(gpu, gpu_scene, *settings)?;
        let taa =
            settings.taa.then(|| Taa::new(gpu, gpu_scene, TaaSettings::default())).transpose()?;
        world.entity_mut(entity).insert(HashCacheState { cache, taa, updated: None });
        Ok(())
    }
}

/// The cache's upkeep before the image: age (eviction), trace (lookups, claims), update.
pub fn update(
    gpu: Res<GpuDevice>,
    gpu_scene: Res<GpuScene>,
    run: Res<Run>,
    clock: Res<FrameClock>,
    scene: Res<sim::ExtractedScene>,
    mut methods: Query<(&mut HashCacheState, &MethodInfo, &mut MethodFrame)>,
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

/// The frame's image: the cache's colour, or TAA's resolve over it.
pub fn resolve(
    gpu: Res<GpuDevice>,
    gpu_scene: Res<GpuScene>,
    clock: Res<FrameClock>,
    mut methods: Query<(&mut HashCacheState, &MethodInfo, &mut MethodFrame)>,
) -> Result<(), BevyError> {
    for (mut state, info, mut frame) in &mut methods {
        let start = Instant::now();
        let state = &mut *state;
        let (timings, jitter) = state.updated.take().unwrap_or_default();
        let out = state
            .cache
            .resolve(&gpu.0, &gpu_scene.0, state.taa.as_mut(), timings, jitter)
            .map_err(|e| method_failed(&info.label, clock.global, e))?;
        let s = out.stats;
        frame.output = Some(MethodOutput {
            stats: vec![
                ("cache_occupancy".into(), s.occupancy()),
                ("cache_used_cells".into(), s.occupied as f64),
                ("cache_evictions".into(), s.evicted as f64),
                ("cache_insertions".into(), s.inserted as f64),
                ("cache_insert_failures".into(), s.insert_failures as f64),
                ("cache_update_paths".into(), s.update_paths as f64),
            ],
            ..MethodOutput::timed(out.radiance, out.motion, &out.timings, out.rays, out.shaded)
        });
        frame.add_cpu(start);
    }
    Ok(())
}
