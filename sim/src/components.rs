//! Components of the world that the renderer sees: geometry instances, lights, the camera.

use bevy_ecs::prelude::*;
use scene::Light;

pub use bevy_ecs::name::Name;

/// A placed copy of shared geometry: several entities may point at one mesh (one BLAS).
#[derive(Component, Clone, Copy, Debug, PartialEq, Eq)]
pub struct MeshInstance {
    /// Index into the scene's mesh list.
    pub mesh: u32,
    /// Index into [`crate::resources::MaterialTable`].
    pub material: u32,
}

/// An analytic light in the entity's local space: positions are transformed as points and
/// directions as vectors by the entity's `GlobalTransform`, so rotating the entity rotates
/// the light.
#[derive(Component, Clone, Copy, Debug, PartialEq)]
pub struct LightSource(pub Light);

/// A multiplier on emitted power, driven by Flash and toggled by events. Lights carry one
/// always; an emissive mesh gets one when an animation or event targets it.
#[derive(Component, Clone, Copy, Debug, PartialEq)]
pub struct Intensity {
    /// Waveform value (1 = as authored).
    pub scale: f32,
    /// Switched off by a toggle event.
    pub on: bool,
}

impl Default for Intensity {
    fn default() -> Self {
        Self { scale: 1.0, on: true }
    }
}

impl Intensity {
    pub fn factor(&self) -> f32 {
        if self.on { self.scale } else { 0.0 }
    }
}

/// A pinhole camera looking down its local -Z with local +Y up.
#[derive(Component, Clone, Copy, Debug, PartialEq)]
pub struct Camera {
    /// Vertical field of view in radians.
    pub vfov: f32,
}

/// Removed from rendering (e.g. the prototype of a flock) but kept for its name and mesh.
#[derive(Component, Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct Hidden;

/// Position in spawn order: extraction lists instances and lights in this order, so
/// instance ids follow the scene file (entity ids themselves are allocated in no useful
/// order).
#[derive(Component, Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord)]
pub struct SpawnOrder(pub u32);
