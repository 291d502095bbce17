//! glTF animations played back: keyframe tracks of node transforms (translation, rotation,
//! scale) and, through KHR_animation_pointer, of light colour and intensity, material factors
//! and the camera's field of view. Sampled at the clock's time with the track's interpolation
//! (glTF's LINEAR, with spherical interpolation of rotations, or STEP).

use bevy_ecs::prelude::*;
use glam::{Quat, Vec3, Vec4};
use scene::Light;

use crate::components::{Camera, LightSource};
use crate::resources::{Clock, MaterialTable};
use crate::transform::Transform;

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Interpolation {
    Linear,
    Step,
}

/// Values at increasing times (seconds); before the first key the first value holds, after the
/// last the last.
#[derive(Clone, Debug, PartialEq)]
pub struct Track<T> {
    pub times: Vec<f32>,
    pub values: Vec<T>,
    pub interpolation: Interpolation,
}

/// What a track's values blend by.
pub trait Blend: Copy {
    fn blend(a: Self, b: Self, s: f32) -> Self;
}

impl Blend for f32 {
    fn blend(a: f32, b: f32, s: f32) -> f32 {
        a + (b - a) * s
    }
}
impl Blend for Vec3 {
    fn blend(a: Vec3, b: Vec3, s: f32) -> Vec3 {
        a.lerp(b, s)
    }
}
impl Blend for Vec4 {
    fn blend(a: Vec4, b: Vec4, s: f32) -> Vec4 {
        a.lerp(b, s)
    }
}
impl Blend for Quat {
    fn blend(a: Quat, b: Quat, s: f32) -> Quat {
        a.slerp(b, s)
    }
}

impl<T: Blend> Track<T> {
    /// Checks what glTF requires of a sampler: as many values as times, at least one key,
    /// strictly increasing finite times.
    pub fn new(
        times: Vec<f32>,
        values: Vec<T>,
        interpolation: Interpolation,
    ) -> Result<Self, String> {
        if times.is_empty() || times.len() != values.len() {
            return Err(format!(
                "{} key times and {} values; expected as many values as times, at least one",
                times.len(),
                values.len()
            ));
        }
        if let Some(w) = times.windows(2).find(|w| !(w[1] > w[0])) {
            return Err(format!(
                "key times {} then {}; expected strictly increasing times",
                w[0], w[1]
            ));
        }
        if times.iter().any(|t| !t.is_finite()) {
            return Err("a key time is not finite; expected finite seconds".into());
        }
        Ok(Self { times, values, interpolation })
    }

    pub fn sample(&self, t: f32) -> T {
        let n = self.times.len();
        if t <= self.times[0] {
            return self.values[0];
        }
        if t >= self.times[n - 1] {
            return self.values[n - 1];
        }
        // The key at or before t: times[i] <= t < times[i + 1].
        let i = self.times.partition_point(|&k| k <= t) - 1;
        match self.interpolation {
            Interpolation::Step => self.values[i],
            Interpolation::Linear => {
                let s = (t - self.times[i]) / (self.times[i + 1] - self.times[i]);
                T::blend(self.values[i], self.values[i + 1], s)
            }
        }
    }
}

/// A node's transform tracks; a missing one leaves that part of the transform alone.
#[derive(Component, Clone, Debug, Default, PartialEq)]
pub struct NodeClip {
    pub translation: Option<Track<Vec3>>,
    pub rotation: Option<Track<Quat>>,
    pub scale: Option<Track<Vec3>>,
}

/// A KHR_lights_punctual light's colour and intensity tracks; the light emits colour x
/// intensity, as at import.
#[derive(Component, Clone, Debug, PartialEq)]
pub struct LightClip {
    pub color: Vec3,
    pub intensity: f32,
    pub color_track: Option<Track<Vec3>>,
    pub intensity_track: Option<Track<f32>>,
}

/// The camera's vertical field of view (radians) over time.
#[derive(Component, Clone, Debug, PartialEq)]
pub struct CameraClip(pub Track<f32>);

/// One animated factor of a material.
#[derive(Clone, Debug, PartialEq)]
pub enum MaterialTrack {
    /// RGBA; the renderer uses RGB.
    BaseColor(Track<Vec4>),
    /// The emissive factor; emission = factor x the material's emissive strength.
    Emissive {
        factor: Track<Vec3>,
        strength: f32,
    },
    Roughness(Track<f32>),
    Metallic(Track<f32>),
}

/// The animated factors of the scene's materials, by material index.
#[derive(Resource, Clone, Debug, Default, PartialEq)]
pub struct MaterialClips(pub Vec<(u32, MaterialTrack)>);

/// Simulate stage, first of the animations (a scenario's own animations and events apply on
/// top): every clip at the clock's time.
pub fn play_clips(
    clock: Res<Clock>,
    mut nodes: Query<(&NodeClip, &mut Transform)>,
    mut lights: Query<(&LightClip, &mut LightSource)>,
    mut cameras: Query<(&CameraClip, &mut Camera)>,
    materials: Option<Res<MaterialClips>>,
    mut table: ResMut<MaterialTable>,
) {
    let t = clock.time();
    for (clip, mut transform) in &mut nodes {
        if let Some(k) = &clip.translation {
            transform.translation = k.sample(t);
        }
        if let Some(k) = &clip.rotation {
            transform.rotation = k.sample(t).normalize();
        }
        if let Some(k) = &clip.scale {
            transform.scale = k.sample(t);
        }
    }
    for (clip, mut source) in &mut lights {
        let color = clip.color_track.as_ref().map_or(clip.color, |k| k.sample(t));
        let intensity = clip.intensity_track.as_ref().map_or(clip.intensity, |k| k.sample(t));
        let power = color * intensity;
        match &mut source.0 {
            Light::Directional { irradiance, .. } => *irradiance = power,
            Light::Point { intensity, .. } | Light::Spot { intensity, .. } => *intensity = power,
        }
    }
    for (clip, mut camera) in &mut cameras {
        camera.vfov = clip.0.sample(t);
    }
    let Some(materials) = materials else { return };
    for (index, track) in &materials.0 {
        let m = &mut table.materials[*index as usize];
        match track {
            MaterialTrack::BaseColor(k) => m.base_color = k.sample(t).truncate(),
            MaterialTrack::Emissive { factor, strength } => {
                m.emission = factor.sample(t) * strength
            }
            MaterialTrack::Roughness(k) => m.roughness = k.sample(t),
            MaterialTrack::Metallic(k) => m.metallic = k.sample(t),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn linear_and_step_tracks_hit_their_keys_and_blend_between() {
        let k =
            Track::new(vec![0.0, 1.0, 3.0], vec![0.0, 2.0, 6.0], Interpolation::Linear).unwrap();
        assert_eq!(k.sample(-1.0), 0.0);
        assert_eq!(k.sample(1.0), 2.0);
        assert_eq!(k.sample(2.0), 4.0);
        assert_eq!(k.sample(9.0), 6.0);
        let s = Track { interpolation: Interpolation::Step, ..k };
        assert_eq!(s.sample(2.9), 2.0);
        assert!(Track::new(vec![0.0, 0.0], vec![1.0, 2.0], Interpolation::Linear).is_err());
        assert!(Track::<f32>::new(vec![0.0], vec![], Interpolation::Linear).is_err());
    }
}
