//! Extract stage: the scene the simulation extracted -> the GPU, uploading only what changed.

use bevy_ecs::prelude::*;
use sim::ExtractedScene;

use super::resources::{FrameClock, GpuDevice, GpuScene};
use super::stage::failed;

/// Takes the simulation's frame number (Simulate advanced it).
pub fn frame_number(mut clock: ResMut<FrameClock>, sim_clock: Res<sim::resources::Clock>) {
    clock.global = sim_clock.frame;
}

/// Uploads the extracted scene's changes. Runs every frame: the camera and instance transforms
/// of the last frame become the previous ones of motion vectors.
pub fn upload_scene(
    gpu: Res<GpuDevice>,
    mut gpu_scene: ResMut<GpuScene>,
    scene: Res<ExtractedScene>,
    clock: Res<FrameClock>,
) -> Result {
    let changes = if scene.is_changed() { scene.changes } else { Default::default() };
    gpu_scene
        .0
        .update_changed(&gpu.0, &scene.scene, changes)
        .map_err(|e| failed(anyhow::anyhow!("uploading the scene of frame {}: {e}", clock.global)))
}
