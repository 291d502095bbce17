//! Volumetric path tracing of a scenario with a medium (media::gpu::VolumePathPass):
//! delta tracking, ratio-tracked shadow rays and, with `mis` set, equiangular sampling of
//! positional lights combined with free-flight sampling by Eq. 9 or Eq. 10 of the
//! jackknife-transmittance paper with the naive, jackknife or Miller et al.'s weights. What the
//! MIS comparison (scenarios/volume_mis.ron) and the dynamic-media scenarios measure against the
//! references (rendered by the same pass with Eq. 9 and jackknife weights at the reference spp).
//! Its motion vectors are zero (the scenarios' cameras are still).

use std::time::Instant;

use anyhow::{Result, bail};
use bevy_ecs::prelude::*;
use media::gpu::{Combination, Eq9Transmittance, MisWeight, ShadowTransmittance};
use render::frame_bindings::FrameBindings;
use serde::{Deserialize, Serialize};

use frame::scene_medium::{SceneMedium, render_volume};
use frame::{FrameClock, GpuDevice, GpuScene, MethodFrame, MethodInfo, Run, Stage, method_failed};
use frame::{MethodOutput, MethodPlugin};

/// `VolumePath(spp: 4, mis: Jackknife, combination: Eq9)`; `shadow: Jackknife` (with
/// `shadow_samples: 10`, `shadow_estimates: 2`, or `shadow_step: 0.5` for an importance-tied N)
/// attenuates shadow rays by the jackknife instead of ratio tracking.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct VolumePathSettings {
    pub spp: u32,
    pub mis: MisWeight,
    pub combination: Combination,
    /// Samples N of each optical-depth estimate of a naive or jackknife weight.
    pub samples: u32,
    pub shadow: ShadowTransmittance,
    /// N of each optical-depth estimate of a jackknife shadow ray.
    pub shadow_samples: u32,
    /// m of a jackknife shadow ray (Eq. 3).
    pub shadow_estimates: u32,
    /// F_Δ of an importance-tied N (Fig. 8d) for jackknife shadow rays.
    pub shadow_step: Option<f32>,
    pub eq9_transmittance: Eq9Transmittance,
}

impl Default for VolumePathSettings {
    fn default() -> Self {
        let d = media::gpu::VolumePathSettings::default();
        Self {
            spp: 4,
            mis: d.mis,
            combination: d.combination,
            samples: d.samples,
            shadow: d.shadow,
            shadow_samples: d.shadow_samples,
            shadow_estimates: d.shadow_estimates,
            shadow_step: d.shadow_step,
            eq9_transmittance: d.eq9_transmittance,
        }
    }
}

impl VolumePathSettings {
    pub fn label(&self) -> String {
        let mis = match self.mis {
            MisWeight::None => "free_flight".to_string(),
            w => format!(
                "{}_{}",
                format!("{w:?}").to_lowercase(),
                format!("{:?}", self.combination).to_lowercase()
            ),
        };
        // Only what differs from the defaults is named, so earlier labels stay.
        let shadow = match self.shadow {
            ShadowTransmittance::RatioTracking => String::new(),
            ShadowTransmittance::TrackLength => "_shadow_track_length".into(),
            ShadowTransmittance::Jackknife => match self.shadow_step {
                Some(step) => format!("_shadow_jackknife_m{}_step{step}", self.shadow_estimates),
                None => {
                    format!("_shadow_jackknife_m{}_n{}", self.shadow_estimates, self.shadow_samples)
                }
            },
        };
        let exact = match self.eq9_transmittance {
            Eq9Transmittance::RatioTracking => "",
            Eq9Transmittance::Exact => "_exact_t",
        };
        format!("volume_pt_{mis}{exact}{shadow}_{}spp", self.spp)
    }

    /// The pass's settings (media's `VolumePathPass`).
    fn settings(&self) -> media::gpu::VolumePathSettings {
        media::gpu::VolumePathSettings {
            mis: self.mis,
            combination: self.combination,
            samples: self.samples,
            shadow: self.shadow,
            shadow_samples: self.shadow_samples,
            shadow_estimates: self.shadow_estimates,
            shadow_step: self.shadow_step,
            eq9_transmittance: self.eq9_transmittance,
        }
    }
}

/// The method's settings and its frame parameters.
#[derive(Component)]
pub struct VolumePath(VolumePathSettings, FrameBindings);

pub struct Plugin;

impl MethodPlugin for Plugin {
    type Settings = VolumePathSettings;
    const NAME: &'static str = "VolumePath";

    fn label(settings: &VolumePathSettings) -> String {
        settings.label()
    }

    fn spp(settings: &VolumePathSettings) -> f64 {
        settings.spp as f64
    }

    fn temporal_window(_settings: &VolumePathSettings) -> Option<f64> {
        Some(1.0)
    }

    fn set_spp(settings: &mut VolumePathSettings, spp: u32) {
        settings.spp = spp;
    }

    fn sees_media() -> bool {
        true
    }

    fn add_systems(schedule: &mut Schedule) {
        schedule.add_systems(render.in_set(Stage::Render));
    }

    fn spawn(world: &mut World, entity: Entity, s: &VolumePathSettings) -> Result<()> {
        if s.spp == 0 {
            bail!("VolumePath: spp 0; expected at least 1 sample per pixel");
        }
        if let Some(problem) = s.settings().problem() {
            bail!("VolumePath: {problem}");
        }
        if !world.contains_resource::<SceneMedium>() {
            bail!(
                "VolumePath: the scenario declares no media; expected media: [(name: ..., kind: ..., ...)]"
            );
        }
        let bindings =
            FrameBindings::new(&world.resource::<GpuDevice>().0, &world.resource::<GpuScene>().0);
        world.entity_mut(entity).insert(VolumePath(s.clone(), bindings));
        Ok(())
    }
}

pub fn render(
    gpu: Res<GpuDevice>,
    gpu_scene: Res<GpuScene>,
    mut medium: ResMut<SceneMedium>,
    run: Res<Run>,
    clock: Res<FrameClock>,
    mut methods: Query<(&VolumePath, &MethodInfo, &mut MethodFrame)>,
) -> Result<(), BevyError> {
    for (method, info, mut frame) in &mut methods {
        let start = Instant::now();
        let (radiance, timings, paths) = render_volume(
            &gpu.0,
            &gpu_scene.0,
            &method.1,
            &mut medium,
            &method.0.settings(),
            method.0.spp,
            run.scenario.seed,
            clock.global,
        )
        .map_err(|e| method_failed(&info.label, clock.global, e))?;
        let motion = vec![[0.0; 2]; radiance.len()];
        frame.output = Some(MethodOutput::timed(radiance, motion, &timings, paths, paths));
        frame.add_cpu(start);
    }
    Ok(())
}
