//! The stable sample cache (the crate's `lib.rs`) as four systems, one per stage of the paper's
//! frame: reproject (forward reprojection and slot reservation), retrace, shade, reconstruct;
//! with `taa: true` the reconstruction is resolved by TAA (taa), as the paper's error
//! figures run every method.

use std::time::Instant;

use crate::SampleCache;
use anyhow::Result;
use bevy_ecs::prelude::*;
use taa::{Taa, TaaSettings};

pub use crate::SampleCacheSettings;

use frame::{FrameClock, GpuDevice, GpuScene, MethodFrame, MethodInfo, Run, Stage, method_failed};
use frame::{MethodImage, MethodOutput, MethodPlugin, temporal_window};

#[derive(Component)]
pub struct SampleCacheState(SampleCache, Option<Taa>);

pub struct Plugin;

impl MethodPlugin for Plugin {
    type Settings = SampleCacheSettings;
    const NAME: &'static str = "SampleCache";
    const STATISTICS: &'static [frame::method::Statistic] = crate::recorded::STATISTICS;

    fn label(settings: &SampleCacheSettings) -> String {
        settings.label()
    }

    fn spp(settings: &SampleCacheSettings) -> f64 {
        // Uniform shading: one path per pixel (validate refuses another rate); adaptive:
        // the budget's rate.
        settings.shading_rate as f64
    }

    fn temporal_window(settings: &SampleCacheSettings) -> Option<f64> {
        // The running mean (alpha 0, the default) has no fixed window: it grows with the run.
        let alpha = if settings.roughness_alpha { 0.1 } else { settings.alpha as f64 };
        if alpha == 0.0 {
            return None;
        }
        let shades = settings.n_target as f64 * temporal_window::exponential(alpha);
        Some(taa::plugin::window_under_taa(shades / settings.shading_rate as f64, settings.taa))
    }

    fn add_systems(schedule: &mut Schedule) {
        schedule
            .add_systems((reproject, retrace, shade, reconstruct).chain().in_set(Stage::Render));
    }

    fn spawn(world: &mut World, entity: Entity, settings: &SampleCacheSettings) -> Result<()> {
        settings.validate().map_err(|e| anyhow::anyhow!("SampleCache: {e}"))?;
        let (gpu, gpu_scene) = (&world.resource::<GpuDevice>().0, &world.resource::<GpuScene>().0);
        let cache = SampleCache::new(gpu, gpu_scene, *settings)?;
        let taa =
            settings.taa.then(|| Taa::new(gpu, gpu_scene, TaaSettings::default())).transpose()?;
        world.entity_mut(entity).insert(SampleCacheState(cache, taa));
        Ok(())
    }
}

/// Runs stage `stage` of every sample cache.
fn stage(
    stage: usize,
    gpu: &GpuDevice,
    gpu_scene: &GpuScene,
    seed: u64,
    clock: &FrameClock,
    methods: &mut Query<(&mut SampleCacheState, &MethodInfo, &mut MethodFrame)>,
) -> Result<(), BevyError> {
    for (mut state, info, mut frame) in methods.iter_mut() {
        let start = Instant::now();
        if stage == 0 {
            state.0.begin_frame(seed, clock.global);
        }
        state
            .0
            .stage(&gpu.0, &gpu_scene.0, stage)
            .map_err(|e| method_failed(&info.label, clock.global, e))?;
        frame.add_cpu(start);
    }
    Ok(())
}

/// Forward reprojection of last frame's samples and reservation of their slots.
pub fn reproject(
    gpu: Res<GpuDevice>,
    gpu_scene: Res<GpuScene>,
    run: Res<Run>,
    clock: Res<FrameClock>,
    mut methods: Query<(&mut SampleCacheState, &MethodInfo, &mut MethodFrame)>,
) -> Result<(), BevyError> {
    stage(0, &gpu, &gpu_scene, run.scenario.seed, &clock, &mut methods)
}

/// Retracing: holes, the slope test's pixels and the base rate (single, multi or adaptive).
pub fn retrace(
    gpu: Res<GpuDevice>,
    gpu_scene: Res<GpuScene>,
    run: Res<Run>,
    clock: Res<FrameClock>,
    mut methods: Query<(&mut SampleCacheState, &MethodInfo, &mut MethodFrame)>,
) -> Result<(), BevyError> {
    stage(1, &gpu, &gpu_scene, run.scenario.seed, &clock, &mut methods)
}

/// Shading of the selected samples (uniform or adaptive rate).
pub fn shade(
    gpu: Res<GpuDevice>,
    gpu_scene: Res<GpuScene>,
    run: Res<Run>,
    clock: Res<FrameClock>,
    mut methods: Query<(&mut SampleCacheState, &MethodInfo, &mut MethodFrame)>,
) -> Result<(), BevyError> {
    stage(2, &gpu, &gpu_scene, run.scenario.seed, &clock, &mut methods)
}

/// The image: each pixel's visible samples averaged; counters and the trace mask.
pub fn reconstruct(
    gpu: Res<GpuDevice>,
    gpu_scene: Res<GpuScene>,
    run: Res<Run>,
    clock: Res<FrameClock>,
    mut methods: Query<(&mut SampleCacheState, &MethodInfo, &mut MethodFrame)>,
) -> Result<(), BevyError> {
    stage(3, &gpu, &gpu_scene, run.scenario.seed, &clock, &mut methods)?;
    for (mut state, info, mut frame) in &mut methods {
        let start = Instant::now();
        let slots = state.0.settings().slots as f64;
        let mut out = state
            .0
            .finish_frame(&gpu.0)
            .map_err(|e| method_failed(&info.label, clock.global, e))?;
        let SampleCacheState(cache, taa) = &mut *state;
        if let Some(taa) = taa {
            let resolved = cache
                .resolve_taa(&gpu.0, taa)
                .map_err(|e| method_failed(&info.label, clock.global, e))?;
            out.radiance = resolved.radiance;
            out.timings.extend(resolved.timings);
        }
        let s = &out.stats;
        let pixels = out.radiance.len().max(1) as f64;
        let stats = vec![
            ("primary_rays".to_string(), s.rays as f64),
            ("new_samples".to_string(), s.new_samples as f64),
            ("purged_samples".to_string(), s.purged as f64),
            ("reprojected_samples".to_string(), s.reprojected as f64),
            ("dropped_samples".to_string(), s.dropped as f64),
            ("visible_per_pixel".to_string(), s.visible as f64 / pixels),
            ("occupancy".to_string(), s.occupied as f64 / (pixels * slots)),
            ("slope_flagged_pixels".to_string(), s.slope_flagged as f64),
        ];
        // Trace mask (red: slope test, green: base rate, blue: hole), as the paper's figure 4.
        let trace_mask = out
            .flags
            .iter()
            .map(|f| {
                let on = |bit: u32| if f & bit != 0 { 1.0 } else { 0.0 };
                [on(crate::FLAG_SLOPE), on(crate::FLAG_BASE), on(crate::FLAG_HOLE), 1.0]
            })
            .collect();
        frame.output = Some(MethodOutput {
            stats,
            images: vec![MethodImage { name: "trace_mask".into(), pixels: trace_mask, hdr: false }],
            ..MethodOutput::timed(
                out.radiance,
                out.motion,
                &out.timings,
                s.all_rays as u64,
                s.shaded as u64,
            )
        });
        frame.add_cpu(start);
    }
    Ok(())
}
