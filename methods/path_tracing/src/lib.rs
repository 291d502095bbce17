//! Plain path tracing at k samples per pixel: the baseline every cache is measured against.

use std::time::Instant;

use anyhow::{Result, bail};
use bevy_ecs::prelude::*;
use render::path_tracer::PathTracer;
use serde::{Deserialize, Serialize};

use frame::{FrameClock, GpuDevice, GpuScene, MethodFrame, MethodInfo, Run, Stage, method_failed};
use frame::{MethodOutput, MethodPlugin};

/// `PathTracing(spp: 4)`.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct PathTracingSettings {
    pub spp: u32,
}

impl PathTracingSettings {
    pub fn label(&self) -> String {
        format!("pt_{}spp", self.spp)
    }
}

/// Its spp and its path tracer (frame parameters, radiance sum, G-buffer, ray counter).
#[derive(Component)]
pub struct PathTracing {
    spp: u32,
    tracer: PathTracer,
}

pub struct Plugin;

impl MethodPlugin for Plugin {
    type Settings = PathTracingSettings;
    const NAME: &'static str = "PathTracing";

    fn label(settings: &PathTracingSettings) -> String {
        settings.label()
    }

    fn spp(settings: &PathTracingSettings) -> f64 {
        settings.spp as f64
    }

    fn temporal_window(_settings: &PathTracingSettings) -> Option<f64> {
        Some(1.0)
    }

    fn set_spp(settings: &mut PathTracingSettings, spp: u32) {
        settings.spp = spp;
    }

    fn add_systems(schedule: &mut Schedule) {
        schedule.add_systems(render.in_set(Stage::Render));
    }

    fn spawn(world: &mut World, entity: Entity, s: &PathTracingSettings) -> Result<()> {
        if s.spp == 0 {
            bail!("PathTracing: spp 0; expected at least 1 sample per pixel");
        }
        let tracer =
            PathTracer::new(&world.resource::<GpuDevice>().0, &world.resource::<GpuScene>().0)?;
        world.entity_mut(entity).insert(PathTracing { spp: s.spp, tracer });
        Ok(())
    }
}

/// G-buffer and `spp` paths per pixel.
pub fn render(
    gpu: Res<GpuDevice>,
    gpu_scene: Res<GpuScene>,
    run: Res<Run>,
    clock: Res<FrameClock>,
    mut methods: Query<(&mut PathTracing, &MethodInfo, &mut MethodFrame)>,
) -> Result<(), BevyError> {
    for (mut pt, info, mut frame) in &mut methods {
        let start = Instant::now();
        let spp = pt.spp;
        let out = pt
            .tracer
            .render(&gpu.0, &gpu_scene.0, spp, run.scenario.seed, clock.global)
            .map_err(|e| method_failed(&info.label, clock.global, e))?;
        frame.output = Some(MethodOutput::timed(
            out.radiance,
            out.gbuffer.motion,
            &out.timings,
            out.rays,
            out.shaded,
        ));
        frame.add_cpu(start);
    }
    Ok(())
}
