//! Rotation of an entity (or a light, through its entity) about an axis through its origin.

use bevy_ecs::prelude::*;
use glam::{Quat, Vec3};

use crate::resources::Clock;
use crate::transform::Transform;

/// Continuous rotation at a constant angular speed.
#[derive(Component, Clone, Copy, Debug, PartialEq)]
pub struct Rotate {
    /// Axis in the parent's space (normalised).
    pub axis: Vec3,
    /// Radians per second.
    pub speed: f32,
}

/// One rotation by `angle` at frame `frame`.
#[derive(Component, Clone, Copy, Debug, PartialEq)]
pub struct RotateOnce {
    pub axis: Vec3,
    /// Radians.
    pub angle: f32,
    pub frame: u32,
}

/// Turns `transform` by `angle` about `axis` (parent space), keeping its position.
pub fn turn(transform: &mut Transform, axis: Vec3, angle: f32) {
    transform.rotation =
        (Quat::from_axis_angle(axis.normalize(), angle) * transform.rotation).normalize();
}

pub fn rotate(clock: Res<Clock>, mut query: Query<(&Rotate, &mut Transform)>) {
    let dt = clock.delta();
    if dt == 0.0 {
        return;
    }
    for (r, mut t) in &mut query {
        turn(&mut t, r.axis, r.speed * dt);
    }
}

pub fn rotate_once(clock: Res<Clock>, mut query: Query<(&RotateOnce, &mut Transform)>) {
    for (r, mut t) in &mut query {
        if r.frame == clock.frame {
            turn(&mut t, r.axis, r.angle);
        }
    }
}
