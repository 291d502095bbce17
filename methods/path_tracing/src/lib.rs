//! Plain path tracing at k samples per pixel: the baseline every cache is measured against.

use std::time::Instant;

use anyhow::{Result, bail};
use bevy_ecs::prelude::*;
use render::path_tracer::{GBuffer, NO_HIT, PathTracer};
use serde::{Deserialize, Serialize};

use frame::{FrameClock, GpuDevice, GpuScene, MethodFrame, MethodInfo, Run, Stage, method_failed};
use frame::{MethodImage, MethodOutput, MethodPlugin};

/// `PathTracing(spp: 4)`.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct PathTracingSettings {
    pub spp: u32,
    /// Also write the primary hit's G-buffer as extra images (`albedo`, `normal`, `depth`,
    /// `emission`): the inputs a denoiser expects beside the noisy radiance and motion vectors.
    #[serde(default, skip_serializing_if = "std::ops::Not::not")]
    pub gbuffer: bool,
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
    gbuffer: bool,
    tracer: PathTracer,
}

pub struct Plugin;

impl MethodPlugin for Plugin {
    type Settings = PathTracingSettings;
    const NAME: &'static str = "PathTracing";
    const MINIMAL_SETTINGS: &'static str = "(spp: 1)";

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
        world.entity_mut(entity).insert(PathTracing { spp: s.spp, gbuffer: s.gbuffer, tracer });
        Ok(())
    }
}

/// G-buffer and `spp` paths per pixel.
pub fn render(
    gpu: Res<GpuDevice>,
    gpu_scene: Res<GpuScene>,
    run: Res<Run>,
    clock: Res<FrameClock>,
    scene: Res<frame::ExtractedScene>,
    mut methods: Query<(&mut PathTracing, &MethodInfo, &mut MethodFrame)>,
) -> Result<(), BevyError> {
    for (mut pt, info, mut frame) in &mut methods {
        let start = Instant::now();
        let spp = pt.spp;
        let out = pt
            .tracer
            .render(&gpu.0, &gpu_scene.0, spp, run.scenario.seed, clock.global)
            .map_err(|e| method_failed(&info.label, clock.global, e))?;
        let images = if pt.gbuffer { gbuffer_images(&out.gbuffer, &scene.scene) } else { vec![] };
        let mut output = MethodOutput::timed(
            out.radiance,
            out.gbuffer.motion,
            &out.timings,
            out.rays,
            out.shaded,
        );
        output.images = images;
        frame.output = Some(output);
        frame.add_cpu(start);
    }
    Ok(())
}

/// The G-buffer as HDR images (RGB, alpha 1): `albedo` (linear base colour, texture included),
/// `normal` (world shading normal towards the camera), `depth` (distance along the pixel-centre
/// ray, R = G = B; +inf on a miss) and `emission` (the emitted radiance the primary hit sees: its
/// material's emission, or the environment on a miss).
pub fn gbuffer_images(g: &GBuffer, scene: &render::scene::SceneDesc) -> Vec<MethodImage> {
    let rgb = |v: [f32; 3]| [v[0], v[1], v[2], 1.0];
    let emission = g
        .instance_id
        .iter()
        .map(|&i| match scene.instances.get(i as usize) {
            Some(inst) if i != NO_HIT => {
                rgb(scene.materials[inst.material as usize].emission.into())
            }
            _ => rgb(scene.environment.into()),
        })
        .collect();
    let image = |name: &str, pixels| MethodImage { name: name.into(), pixels, hdr: true };
    vec![
        image("albedo", g.albedo.iter().map(|&a| rgb(a)).collect()),
        image("normal", g.normal.iter().map(|&n| rgb(n)).collect()),
        image("depth", g.depth.iter().map(|&d| [d, d, d, 1.0]).collect()),
        image("emission", emission),
    ]
}
