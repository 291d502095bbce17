//! Primary-ray transmittance images of a participating medium (the paper's Figs. 8
//! and 10): one instance per transmittance estimator (media::Estimator), `spp` estimates per
//! pixel along the camera ray through the pixel centre. Its image is the mean transmittance;
//! its extra images are the bias map (mean − exact) and the per-pixel standard deviation of one
//! estimate; its stats are the density lookups per pixel and estimate (counted on the GPU),
//! mean |bias|, the noise-corrected RMS bias (`media::image::rms_bias`) and mean std. The exact transmittance comes from regular tracking on the CPU
//! (exact for the nearest-neighbour voxels; the paper uses 2^18 spp). A scenario without
//! this method builds no medium and runs no media pass.

use std::time::Instant;

use anyhow::{Result, anyhow, bail};
use bevy_ecs::prelude::*;
use media::gpu::{GpuMedium, ImagePass};
use media::image::{ImageKey, directions, exact, reduce, rms_bias};
use media::{DensityGrid, Estimator, Medium};
use render::frame::CameraBasis;
use serde::{Deserialize, Serialize};

use frame::{FrameClock, GpuDevice, MethodFrame, MethodInfo, Run, Stage, method_failed};
use frame::{MethodImage, MethodOutput, MethodPlugin};

#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct VolumeTransmittanceSettings {
    pub estimator: Estimator,
    /// Estimates per pixel per frame.
    pub spp: u32,
    /// The scenario's medium by name; the first one when unset.
    pub medium: Option<String>,
}

impl Default for VolumeTransmittanceSettings {
    fn default() -> Self {
        Self { estimator: Estimator::Jackknife { samples: 8 }, spp: 16, medium: None }
    }
}

impl VolumeTransmittanceSettings {
    pub fn label(&self) -> String {
        format!("volume_{}_{}spp", self.estimator.label(), self.spp)
    }
}

#[derive(Component)]
pub struct VolumeState {
    medium: Medium,
    gpu_medium: GpuMedium,
    pass: ImagePass,
    settings: VolumeTransmittanceSettings,
}

pub struct Plugin;

impl MethodPlugin for Plugin {
    type Settings = VolumeTransmittanceSettings;
    const NAME: &'static str = "VolumeTransmittance";
    const STATISTICS: &'static [frame::method::Statistic] = crate::recorded::STATISTICS;
    const COMPUTATIONS: &'static [frame::method::DeclaredComputation] = crate::table1::COMPUTATIONS;

    fn label(settings: &VolumeTransmittanceSettings) -> String {
        settings.label()
    }

    fn spp(settings: &VolumeTransmittanceSettings) -> f64 {
        settings.spp as f64
    }

    fn temporal_window(_settings: &VolumeTransmittanceSettings) -> Option<f64> {
        Some(1.0)
    }

    fn set_spp(settings: &mut VolumeTransmittanceSettings, spp: u32) {
        settings.spp = spp;
    }

    fn sees_media() -> bool {
        true
    }

    fn add_systems(schedule: &mut Schedule) {
        schedule.add_systems(render.in_set(Stage::Render));
    }

    fn spawn(
        world: &mut World,
        entity: Entity,
        settings: &VolumeTransmittanceSettings,
    ) -> Result<()> {
        if settings.spp == 0 {
            bail!("VolumeTransmittance: spp 0; expected at least 1 estimate per pixel");
        }
        if let media::Estimator::JackknifeTied { step } = settings.estimator
            && !(step.is_finite() && step > 0.0)
        {
            bail!("VolumeTransmittance: JackknifeTied(step: {step}); expected a finite F_Δ > 0");
        }
        let media = &world.resource::<Run>().scenario.media;
        let desc = match &settings.medium {
            Some(name) => media.iter().find(|m| &m.name == name).ok_or_else(|| anyhow!("VolumeTransmittance: no medium named '{name}' in the scenario's media"))?,
            None => media.first().ok_or_else(|| anyhow!("VolumeTransmittance: the scenario declares no media; expected media: [(name: ..., kind: ..., ...)]"))?,
        };
        let medium = Medium::with_super_voxel(DensityGrid::from_desc(desc), desc.super_voxel);
        let gpu = &world.resource::<GpuDevice>().0;
        let gpu_medium = GpuMedium::new(gpu, &medium);
        let pass = ImagePass::new(gpu, &gpu_medium)?;
        world.entity_mut(entity).insert(VolumeState {
            medium,
            gpu_medium,
            pass,
            settings: settings.clone(),
        });
        Ok(())
    }
}

pub fn render(
    gpu: Res<GpuDevice>,
    run: Res<Run>,
    scene: Res<sim::ExtractedScene>,
    clock: Res<FrameClock>,
    mut methods: Query<(&VolumeState, &MethodInfo, &mut MethodFrame)>,
) -> Result<(), BevyError> {
    let (w, h) = run.scenario.resolution;
    let camera = CameraBasis::new(&scene.scene.camera, w, h);
    let dirs = directions(&camera, w, h);
    for (state, info, mut frame) in &mut methods {
        let start = Instant::now();
        let key = ImageKey {
            seed: run.scenario.seed as u32,
            frame: clock.global,
            spp: state.settings.spp,
        };
        let (estimates, timings) = state
            .pass
            .run(
                &gpu.0,
                &state.gpu_medium,
                camera.position,
                &dirs,
                w,
                state.settings.estimator,
                key,
            )
            .map_err(|e| method_failed(&info.label, clock.global, e))?;
        let stats = reduce(&estimates, key.spp);
        let reference = exact(&state.medium, camera.position, &dirs);
        let n = dirs.len() as f64;
        let gray = |v: f32| [v, v, v, 1.0];
        let bias: Vec<f32> = stats.mean.iter().zip(&reference).map(|(m, r)| m - r).collect();
        let mean_abs_bias = bias.iter().map(|b| f64::from(b.abs())).sum::<f64>() / n;
        let rms_bias = rms_bias(&stats, &reference, key.spp);
        let mean_std = stats.std.iter().map(|&s| f64::from(s)).sum::<f64>() / n;
        let lookups = stats.lookups.iter().map(|&l| f64::from(l)).sum::<f64>() / n;
        let rays = estimates.len() as u64;
        frame.output = Some(MethodOutput {
            stats: vec![
                ("lookups_per_estimate".into(), lookups),
                ("mean_abs_bias".into(), mean_abs_bias),
                ("rms_bias".into(), rms_bias),
                ("mean_std".into(), mean_std),
            ],
            images: vec![
                MethodImage {
                    name: "bias".into(),
                    pixels: bias.iter().map(|&b| gray(b)).collect(),
                    hdr: true,
                },
                MethodImage {
                    name: "std".into(),
                    pixels: stats.std.iter().map(|&s| gray(s)).collect(),
                    hdr: true,
                },
                MethodImage {
                    name: "exact".into(),
                    pixels: reference.iter().map(|&r| gray(r)).collect(),
                    hdr: true,
                },
            ],
            ..MethodOutput::timed(
                stats.mean.iter().map(|&m| gray(m)).collect(),
                vec![[0.0; 2]; dirs.len()],
                &timings,
                rays,
                rays,
            )
        });
        frame.add_cpu(start);
    }
    Ok(())
}
