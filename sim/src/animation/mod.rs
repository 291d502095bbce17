//! Animation systems: each a component plus a system, run at the fixed time step.

pub mod boids;
pub mod clips;
pub mod events;
pub mod flash;
pub mod keyframes;
pub mod rotate;

pub use boids::{Boid, Flock, FlockParams, flock, initial_boids};
pub use clips::{
    CameraClip, Interpolation, LightClip, MaterialClips, MaterialTrack, NodeClip, Track, play_clips,
};
pub use events::{EventAction, ScheduledEvent, ScheduledEvents, apply_events};
pub use flash::{Flash, Waveform, flash};
pub use keyframes::{CameraKey, CameraPath, Keyframe, Keyframes, camera_path, keyframes};
pub use rotate::{Rotate, RotateOnce, rotate, rotate_once};
