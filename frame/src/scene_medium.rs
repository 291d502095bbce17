//! The scenario's participating media in the frame: every declared medium, baked on
//! load and at every frame whose animation state changed (its grid and super-voxel grid rebuilt,
//! `media::Medium::new`), on the GPU together for the volumetric path tracer
//! (media::gpu::VolumePathPass, where their extinctions add) that renders the references of a
//! scenario with media and the `VolumePath` method. A scenario without media has no
//! `SceneMedium`: nothing here runs and the path tracer renders its references as before.

use bevy_ecs::prelude::*;
use glam::Vec3;
use media::gpu::{GpuMedium, MediumOptics, MisWeight, VolumePathPass, VolumePathSettings};
use media::mesh_inside::MeshInside;
use media::{DensityGrid, Medium};
use scene::{MediumDesc, MediumState};

use super::resources::GpuDevice;
use super::stage::failed;

/// The references' settings: Eq. 9 with the jackknife weights (unbiased, Appendix D) and
/// ratio-tracked shadow rays.
pub const REFERENCE_SETTINGS: VolumePathSettings = VolumePathSettings {
    mis: MisWeight::Jackknife,
    combination: media::gpu::Combination::Eq9,
    shadow: media::gpu::ShadowTransmittance::RatioTracking,
    samples: 4,
    shadow_samples: 10,
    shadow_estimates: 2,
    shadow_step: None,
    eq9_transmittance: media::gpu::Eq9Transmittance::RatioTracking,
};

#[derive(Resource)]
pub struct SceneMedium {
    pub descs: Vec<MediumDesc>,
    /// The states the GPU holds, one per medium.
    pub states: Vec<MediumState>,
    /// Each medium's mesh-bound inside test, built once (the OBJ is read at load only).
    bounds: Vec<Option<MeshInside>>,
    /// Each medium baked at its state; a change rebakes only the media whose state changed.
    baked: Vec<Medium>,
    pub gpu: GpuMedium,
    /// Built on first use (references, the VolumePath method).
    pass: Option<VolumePathPass>,
}

fn bake(desc: &MediumDesc, state: &MediumState, bound: Option<&MeshInside>) -> Medium {
    Medium::with_super_voxel(DensityGrid::from_state_within(desc, state, bound), desc.super_voxel)
}

impl SceneMedium {
    /// `descs`: 1 to media::gpu::MAX_MEDIA media (playback checks the count first).
    pub fn new(gpu: &render::gpu::Gpu, descs: &[MediumDesc]) -> Self {
        let states: Vec<MediumState> = descs.iter().map(|d| d.at(0.0)).collect();
        let bounds: Vec<Option<MeshInside>> = descs.iter().map(DensityGrid::bound_of).collect();
        let baked: Vec<Medium> = descs
            .iter()
            .zip(&states)
            .zip(&bounds)
            .map(|((d, s), b)| bake(d, s, b.as_ref()))
            .collect();
        let gpu = GpuMedium::several(gpu, &baked.iter().collect::<Vec<_>>());
        Self { descs: descs.to_vec(), states, bounds, baked, gpu, pass: None }
    }

    /// Albedo and emission (none: zero) of each declared medium.
    pub fn optics(&self) -> Vec<MediumOptics> {
        self.descs
            .iter()
            .map(|d| MediumOptics { albedo: d.albedo, emission: d.emission.unwrap_or(Vec3::ZERO) })
            .collect()
    }

    /// The volumetric path tracing pass, compiled on first use.
    pub fn pass(
        &mut self,
        gpu: &render::gpu::Gpu,
        scene: &render::scene_gpu::SceneGpu,
    ) -> anyhow::Result<&VolumePathPass> {
        if self.pass.is_none() {
            self.pass = Some(VolumePathPass::new(gpu, scene, &self.gpu)?);
        }
        Ok(self.pass.as_ref().expect("built above"))
    }

    /// What the reference cache keys a frame's media by: their declarations and current states.
    pub fn cache_key(&self) -> String {
        let media: Vec<String> =
            self.descs.iter().zip(&self.states).map(|(d, s)| format!("{d:?} {s:?}")).collect();
        format!("{} {:?}", media.join(" "), REFERENCE_SETTINGS)
    }
}

/// Extract stage: the media at the simulated time, rebaked and uploaded when one changed.
pub fn upload_medium(
    gpu: Res<GpuDevice>,
    medium: Option<ResMut<SceneMedium>>,
    clock: Res<sim::resources::Clock>,
) -> Result {
    let Some(mut medium) = medium else { return Ok(()) };
    let states: Vec<MediumState> = medium.descs.iter().map(|d| d.at(clock.time())).collect();
    if states != medium.states {
        for (d, state) in medium.descs.iter().zip(&states) {
            if !(state.box_min.cmplt(state.box_max).all() && state.sigma_t.is_finite()) {
                return Err(failed(anyhow::anyhow!(
                    "medium '{}' at frame {}: degenerate state {state:?}",
                    d.name,
                    clock.frame
                )));
            }
        }
        let medium = &mut *medium;
        for (i, state) in states.into_iter().enumerate() {
            if state != medium.states[i] {
                medium.baked[i] = bake(&medium.descs[i], &state, medium.bounds[i].as_ref());
                medium.states[i] = state;
            }
        }
        medium.gpu = GpuMedium::several(&gpu.0, &medium.baked.iter().collect::<Vec<_>>());
    }
    Ok(())
}

/// `spp` paths per pixel of the current scene and medium with the caller's frame parameters:
/// (radiance with alpha 1, timings, paths).
#[allow(clippy::too_many_arguments)]
pub fn render_volume(
    gpu: &render::gpu::Gpu,
    scene: &render::scene_gpu::SceneGpu,
    bindings: &render::frame_bindings::FrameBindings,
    medium: &mut SceneMedium,
    settings: &VolumePathSettings,
    spp: u32,
    seed: u64,
    frame: u32,
) -> anyhow::Result<(Vec<[f32; 4]>, Vec<render::timing::PassTiming>, u64)> {
    let optics = medium.optics();
    medium.pass(gpu, scene)?;
    let pass = medium.pass.as_ref().expect("built above");
    let image = pass
        .render(gpu, scene, bindings, &medium.gpu, &optics, settings, spp, seed, frame)
        .map_err(|e| anyhow::anyhow!(e))?;
    Ok((image.mean.iter().map(|c| [c[0], c[1], c[2], 1.0]).collect(), image.timings, image.paths))
}
