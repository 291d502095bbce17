//! The scenario's participating medium in the frame (issue 13): the first declared medium,
//! baked on load and at every frame whose animation state changed (its grid and super-voxel
//! grid rebuilt, `media::Medium::new`), on the GPU for the volumetric path tracer
//! (media::gpu::VolumePathPass) that renders the references of a scenario with media and the
//! `VolumePath` method. A scenario without media has no `SceneMedium`: nothing here runs and the
//! path tracer renders its references as before.

use bevy_ecs::prelude::*;
use glam::Vec3;
use media::gpu::{GpuMedium, MediumOptics, MisWeight, VolumePathPass, VolumePathSettings};
use media::{DensityGrid, Medium};
use scene::{MediumDesc, MediumState};

use super::resources::{GpuDevice, Tracer};
use super::stage::failed;

/// The references' settings: Eq. 9 with the jackknife weights (unbiased, Appendix D) and
/// ratio-tracked shadow rays.
pub const REFERENCE_SETTINGS: VolumePathSettings = VolumePathSettings {
    mis: MisWeight::Jackknife,
    combination: media::gpu::Combination::Eq9,
    shadow: media::gpu::ShadowTransmittance::RatioTracking,
    samples: 4,
};

#[derive(Resource)]
pub struct SceneMedium {
    pub desc: MediumDesc,
    /// The state the GPU holds.
    pub state: MediumState,
    pub gpu: GpuMedium,
    /// Built on first use (references, the VolumePath method).
    pass: Option<VolumePathPass>,
}

impl SceneMedium {
    pub fn new(gpu: &render::gpu::Gpu, desc: &MediumDesc) -> Self {
        let state = desc.at(0.0);
        let medium = Medium::new(DensityGrid::from_state(desc, &state));
        Self { desc: desc.clone(), state, gpu: GpuMedium::new(gpu, &medium), pass: None }
    }

    /// Albedo and emission (none: zero) of the declared medium.
    pub fn optics(&self) -> MediumOptics {
        MediumOptics { albedo: self.desc.albedo, emission: self.desc.emission.unwrap_or(Vec3::ZERO) }
    }

    /// The volumetric path tracing pass, compiled on first use.
    pub fn pass(&mut self, gpu: &render::gpu::Gpu, tracer: &render::path_tracer::PathTracer) -> anyhow::Result<&VolumePathPass> {
        if self.pass.is_none() {
            self.pass = Some(VolumePathPass::new(gpu, tracer, &self.gpu)?);
        }
        Ok(self.pass.as_ref().expect("built above"))
    }

    /// What the reference cache keys a frame's medium by: its declaration and current state.
    pub fn cache_key(&self) -> String {
        format!("{:?} {:?} {:?}", self.desc, self.state, REFERENCE_SETTINGS)
    }
}

/// Extract stage: the medium at the simulated time, rebaked and uploaded when it changed.
pub fn upload_medium(gpu: Res<GpuDevice>, medium: Option<ResMut<SceneMedium>>, clock: Res<sim::resources::Clock>) -> Result {
    let Some(mut medium) = medium else { return Ok(()) };
    let state = medium.desc.at(clock.time());
    if state != medium.state {
        if !(state.box_min.cmplt(state.box_max).all() && state.sigma_t.is_finite()) {
            return Err(failed(anyhow::anyhow!("medium '{}' at frame {}: degenerate state {state:?}", medium.desc.name, clock.frame)));
        }
        let baked = Medium::new(DensityGrid::from_state(&medium.desc, &state));
        medium.gpu = GpuMedium::new(&gpu.0, &baked);
        medium.state = state;
    }
    Ok(())
}

/// `spp` paths per pixel of the current scene and medium: (radiance with alpha 1, timings, paths).
pub fn render_volume(
    gpu: &render::gpu::Gpu,
    tracer: &Tracer,
    medium: &mut SceneMedium,
    settings: &VolumePathSettings,
    spp: u32,
    seed: u64,
    frame: u32,
) -> anyhow::Result<(Vec<[f32; 4]>, Vec<render::timing::PassTiming>, u64)> {
    let optics = medium.optics();
    medium.pass(gpu, &tracer.0)?;
    let pass = medium.pass.as_ref().expect("built above");
    let image = pass.render(gpu, &tracer.0, &medium.gpu, optics, settings, spp, seed, frame).map_err(|e| anyhow::anyhow!(e))?;
    Ok((image.mean.iter().map(|c| [c[0], c[1], c[2], 1.0]).collect(), image.timings, image.paths))
}
