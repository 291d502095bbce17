//! A pass's pipeline compiled for the scene's features, compiled again when the scene has others
//! (a light kind gained or lost, a deeper BVH), as the shading library's passes are
//! (`PassLibrary::specialise`). The volumetric path tracer and the subsurface random walk bind a
//! group of their own beside the library's, so each holds its pipeline here.

use std::sync::Mutex;

use render::scene_features::SceneFeatures;

pub(super) struct SpecialisedPipeline(Mutex<(SceneFeatures, wgpu::ComputePipeline)>);

impl SpecialisedPipeline {
    pub(super) fn new<E>(
        features: SceneFeatures,
        compile: impl FnOnce(SceneFeatures) -> Result<wgpu::ComputePipeline, E>,
    ) -> Result<Self, E> {
        Ok(Self(Mutex::new((features, compile(features)?))))
    }

    /// The pipeline for `features`, compiled by `compile` if the held one is for others.
    pub(super) fn get<E>(
        &self,
        features: SceneFeatures,
        compile: impl FnOnce(SceneFeatures) -> Result<wgpu::ComputePipeline, E>,
    ) -> Result<wgpu::ComputePipeline, E> {
        let mut held = self.0.lock().unwrap_or_else(|e| e.into_inner());
        if held.0 != features {
            *held = (features, compile(features)?);
        }
        Ok(held.1.clone())
    }

    /// The features the pipeline was last compiled for.
    pub(super) fn features(&self) -> SceneFeatures {
        self.0.lock().unwrap_or_else(|e| e.into_inner()).0
    }
}
