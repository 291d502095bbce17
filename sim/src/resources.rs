//! World-wide resources: materials, environment, clock, random numbers.

use bevy_ecs::prelude::*;
use glam::Vec3;
use scene::Material;

use crate::rng::Rng;

/// The material table; events may change entries, instances refer to them by index.
#[derive(Resource, Clone, Debug, Default, PartialEq)]
pub struct MaterialTable {
    pub materials: Vec<Material>,
    /// One name per material (may be empty for unnamed glTF materials).
    pub names: Vec<String>,
}

impl MaterialTable {
    pub fn push(&mut self, name: impl Into<String>, material: Material) -> u32 {
        self.names.push(name.into());
        self.materials.push(material);
        (self.materials.len() - 1) as u32
    }

    pub fn index_of(&self, name: &str) -> Option<u32> {
        self.names.iter().position(|n| n == name).map(|i| i as u32)
    }
}

/// Constant radiance of rays that leave the scene.
#[derive(Resource, Clone, Copy, Debug, Default, PartialEq)]
pub struct Environment(pub Vec3);

/// Fixed simulation step and the frame being simulated.
#[derive(Resource, Clone, Copy, Debug, PartialEq)]
pub struct Clock {
    /// Seconds per frame.
    pub time_step: f32,
    /// Frame counter; frame 0 is the initial state.
    pub frame: u32,
}

impl Clock {
    /// Simulated time of the current frame in seconds.
    pub fn time(&self) -> f32 {
        self.frame as f32 * self.time_step
    }

    /// Time advanced by this step (zero when setting up frame 0).
    pub fn delta(&self) -> f32 {
        if self.frame == 0 { 0.0 } else { self.time_step }
    }
}

/// The scenario's seed and a generator for draws made in sequence.
#[derive(Resource, Clone, Debug, PartialEq)]
pub struct SimRng {
    pub seed: u64,
    pub rng: Rng,
}

impl SimRng {
    pub fn new(seed: u64) -> Self {
        Self { seed, rng: Rng::seeded(seed) }
    }
}

/// The camera entity that renders.
#[derive(Resource, Clone, Copy, Debug, PartialEq, Eq)]
pub struct ActiveCamera(pub Entity);
