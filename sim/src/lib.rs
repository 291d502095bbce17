//! The world: ECS components, built-in scenes, scenario files, glTF import, animation systems.
//!
//! A [`Scenario`] (RON) names a scene (built-in or glTF), its animations and events; a
//! [`Simulation`] spawns it into a bevy_ecs world, steps it at a fixed time step and
//! extracts a `scene::SceneDesc` per frame.

pub mod animation;
pub mod components;
pub mod extract;
pub mod finite;
pub mod gltf_animation;
pub mod gltf_import;
pub mod meaningless;
pub mod resources;
pub mod rng;
pub mod scenario;
pub mod scenario_file;
pub mod scenes;
pub mod simulation;
pub mod template;
pub mod transform;

pub use scenario::{
    MethodEntry, ReferenceFrames, ReferenceSpec, Region, Scenario, ScenarioError, SceneSource,
};
pub use simulation::{
    ExtractedScene, SimError, Simulation, advance_clock, animation_systems, extract_scene,
};
