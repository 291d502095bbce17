//! TAA over jittered 1 spp path tracing (the crate's `lib.rs`): the temporal baseline. Two
//! systems: the jittered trace, then the resolve (reprojection, clamp, blend).

use std::time::Instant;

use crate::Taa;
use anyhow::Result;
use bevy_ecs::prelude::*;
use render::timing::PassTiming;

pub use crate::TaaSettings;

use frame::{FrameClock, GpuDevice, GpuScene, MethodFrame, MethodInfo, Run, Stage, method_failed};
use frame::{MethodOutput, MethodPlugin, temporal_window};

#[derive(Component)]
pub struct TaaState {
    taa: Taa,
    /// The trace pass's time this frame, until the resolve reports it.
    traced: Option<Vec<PassTiming>>,
}

pub struct Plugin;

impl MethodPlugin for Plugin {
    type Settings = TaaSettings;
    const NAME: &'static str = "Taa";

    fn label(_settings: &TaaSettings) -> String {
        "taa".into()
    }

    fn spp(_settings: &TaaSettings) -> f64 {
        1.0
    }

    fn temporal_window(settings: &TaaSettings) -> Option<f64> {
        Some(temporal_window::exponential(settings.alpha as f64))
    }

    fn add_systems(schedule: &mut Schedule) {
        schedule.add_systems((trace, resolve).chain().in_set(Stage::Render));
    }

    fn spawn(world: &mut World, entity: Entity, settings: &TaaSettings) -> Result<()> {
        settings.validate()?;
        let taa =
            Taa::new(&world.resource::<GpuDevice>().0, &world.resource::<GpuScene>().0, *settings)?;
        world.entity_mut(entity).insert(TaaState { taa, traced: None });
        Ok(())
    }
}

/// Jittered 1 spp path tracing into the current colour.
pub fn trace(
    gpu: Res<GpuDevice>,
    gpu_scene: Res<GpuScene>,
    run: Res<Run>,
    clock: Res<FrameClock>,
    mut methods: Query<(&mut TaaState, &MethodInfo, &mut MethodFrame)>,
) -> Result<(), BevyError> {
    for (mut state, info, mut frame) in &mut methods {
        let start = Instant::now();
        let t = state
            .taa
            .trace(&gpu.0, &gpu_scene.0, run.scenario.seed, clock.global)
            .map_err(|e| method_failed(&info.label, clock.global, e))?;
        state.traced = Some(t);
        frame.add_cpu(start);
    }
    Ok(())
}

/// Reprojection of the history, neighbourhood clamp, exponential blend.
pub fn resolve(
    gpu: Res<GpuDevice>,
    clock: Res<FrameClock>,
    mut methods: Query<(&mut TaaState, &MethodInfo, &mut MethodFrame)>,
) -> Result<(), BevyError> {
    for (mut state, info, mut frame) in &mut methods {
        let start = Instant::now();
        let traced = state.traced.take().unwrap_or_default();
        let out = state
            .taa
            .resolve(&gpu.0, traced)
            .map_err(|e| method_failed(&info.label, clock.global, e))?;
        let n = out.history_length.len().max(1) as f64;
        let rejected = out.history_length.iter().filter(|&&l| l <= 1.0).count() as f64 / n;
        let mean_length = out.history_length.iter().map(|&l| l as f64).sum::<f64>() / n;
        frame.output = Some(MethodOutput {
            stats: vec![
                ("history_rejected".into(), rejected),
                ("history_length_mean".into(), mean_length),
            ],
            ..MethodOutput::timed(out.radiance, out.motion, &out.timings, out.rays, out.shaded)
        });
        frame.add_cpu(start);
    }
    Ok(())
}

/// The temporal window of a method's filter of `window` frames, then, `under` TAA, TAA's
/// default blend in series (the caches that run under TAA use its default settings).
pub fn window_under_taa(window: f64, under: bool) -> f64 {
    if under {
        temporal_window::in_series(
            window,
            temporal_window::exponential(TaaSettings::default().alpha as f64),
        )
    } else {
        window
    }
}
