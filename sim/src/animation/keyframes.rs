//! Keyframed transforms (linear translation/scale, slerp rotation) and camera paths.

use bevy_ecs::prelude::*;
use glam::Vec3;

use crate::components::Camera;
use crate::resources::Clock;
use crate::transform::Transform;

#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Keyframe {
    /// Frame number (fractional allowed).
    pub frame: f32,
    pub transform: Transform,
}

/// Transform keys sorted by frame; before the first key the first holds, after the last the
/// last holds (or the track repeats when `repeat`).
#[derive(Component, Clone, Debug, PartialEq)]
pub struct Keyframes {
    pub keys: Vec<Keyframe>,
    pub repeat: bool,
}

/// Where frame `f` falls: the two surrounding keys' indices and the blend between them.
fn locate(frames: &[f32], f: f32, repeat: bool) -> (usize, usize, f32) {
    let (first, last) = (frames[0], frames[frames.len() - 1]);
    let f = if repeat && last > first { first + (f - first).rem_euclid(last - first) } else { f };
    if f <= first {
        return (0, 0, 0.0);
    }
    if f >= last {
        let n = frames.len() - 1;
        return (n, n, 0.0);
    }
    let i = frames.windows(2).position(|w| f >= w[0] && f < w[1]).unwrap_or(0);
    let span = frames[i + 1] - frames[i];
    (i, i + 1, if span > 0.0 { (f - frames[i]) / span } else { 0.0 })
}

impl Keyframes {
    pub fn sample(&self, frame: f32) -> Transform {
        let frames: Vec<f32> = self.keys.iter().map(|k| k.frame).collect();
        let (a, b, s) = locate(&frames, frame, self.repeat);
        self.keys[a].transform.interpolate(&self.keys[b].transform, s)
    }
}

#[derive(Clone, Copy, Debug, PartialEq)]
pub struct CameraKey {
    pub frame: f32,
    pub position: Vec3,
    pub target: Vec3,
    /// Vertical field of view in radians.
    pub vfov: f32,
}

/// A camera flying through look-at keys: position and target are interpolated linearly,
/// so the view direction turns smoothly between keys.
#[derive(Component, Clone, Debug, PartialEq)]
pub struct CameraPath {
    pub keys: Vec<CameraKey>,
    pub repeat: bool,
}

impl CameraPath {
    pub fn sample(&self, frame: f32) -> (Transform, f32) {
        let frames: Vec<f32> = self.keys.iter().map(|k| k.frame).collect();
        let (a, b, s) = locate(&frames, frame, self.repeat);
        let (ka, kb) = (&self.keys[a], &self.keys[b]);
        let position = ka.position.lerp(kb.position, s);
        let target = ka.target.lerp(kb.target, s);
        let vfov = ka.vfov + (kb.vfov - ka.vfov) * s;
        (Transform::looking_at(position, target, Vec3::Y), vfov)
    }
}

pub fn keyframes(clock: Res<Clock>, mut query: Query<(&Keyframes, &mut Transform)>) {
    for (k, mut t) in &mut query {
        let sampled = k.sample(clock.frame as f32);
        if *t != sampled {
            *t = sampled;
        }
    }
}

pub fn camera_path(
    clock: Res<Clock>,
    mut query: Query<(&CameraPath, &mut Transform, &mut Camera)>,
) {
    for (path, mut t, mut camera) in &mut query {
        let (sampled, vfov) = path.sample(clock.frame as f32);
        if *t != sampled {
            *t = sampled;
        }
        if camera.vfov != vfov {
            camera.vfov = vfov;
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use glam::Quat;

    #[test]
    fn keyframes_interpolate_linearly_and_slerp() {
        let k = Keyframes {
            keys: vec![
                Keyframe { frame: 0.0, transform: Transform::IDENTITY },
                Keyframe {
                    frame: 10.0,
                    transform: Transform::from_trs(
                        Vec3::new(2.0, 0.0, 0.0),
                        Quat::from_rotation_y(1.0),
                        Vec3::splat(3.0),
                    ),
                },
            ],
            repeat: false,
        };
        let mid = k.sample(5.0);
        assert!((mid.translation - Vec3::new(1.0, 0.0, 0.0)).length() < 1e-6);
        assert!((mid.scale - Vec3::splat(2.0)).length() < 1e-6);
        assert!(mid.rotation.angle_between(Quat::from_rotation_y(0.5)) < 1e-4);
        let quarter = k.sample(2.5);
        assert!(quarter.rotation.angle_between(Quat::from_rotation_y(0.25)) < 1e-4);
        assert_eq!(k.sample(-3.0), Transform::IDENTITY);
        assert_eq!(k.sample(42.0), k.keys[1].transform);
        let looping = Keyframes { repeat: true, ..k.clone() };
        assert!((looping.sample(12.5).translation - Vec3::new(0.5, 0.0, 0.0)).length() < 1e-5);
    }

    #[test]
    fn camera_path_looks_at_interpolated_target() {
        let path = CameraPath {
            keys: vec![
                CameraKey { frame: 0.0, position: Vec3::ZERO, target: Vec3::NEG_Z, vfov: 1.0 },
                CameraKey {
                    frame: 4.0,
                    position: Vec3::new(4.0, 0.0, 0.0),
                    target: Vec3::new(4.0, 0.0, -1.0),
                    vfov: 0.5,
                },
            ],
            repeat: false,
        };
        let (t, vfov) = path.sample(1.0);
        assert!((t.translation - Vec3::new(1.0, 0.0, 0.0)).length() < 1e-6);
        assert!((t.rotation * Vec3::NEG_Z - Vec3::NEG_Z).length() < 1e-5);
        assert!((vfov - 0.875).abs() < 1e-6);
    }
}
