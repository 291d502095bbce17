//! Local transforms, the hierarchy (bevy_ecs's `ChildOf`/`Children`) and world-space
//! propagation.

use bevy_ecs::prelude::*;
use glam::{Mat3, Mat4, Quat, Vec3};

/// Transform relative to the parent (or the world for roots): scale, then rotate, then
/// translate.
#[derive(Component, Clone, Copy, Debug, PartialEq)]
pub struct Transform {
    pub translation: Vec3,
    pub rotation: Quat,
    pub scale: Vec3,
}

impl Default for Transform {
    fn default() -> Self {
        Self::IDENTITY
    }
}

impl Transform {
    pub const IDENTITY: Self =
        Self { translation: Vec3::ZERO, rotation: Quat::IDENTITY, scale: Vec3::ONE };

    pub fn from_translation(translation: Vec3) -> Self {
        Self { translation, ..Self::IDENTITY }
    }

    pub fn from_trs(translation: Vec3, rotation: Quat, scale: Vec3) -> Self {
        Self { translation, rotation, scale }
    }

    /// Decomposes an affine matrix (glTF `matrix` nodes); shear is lost.
    pub fn from_matrix(m: Mat4) -> Self {
        let (scale, rotation, translation) = m.to_scale_rotation_translation();
        Self { translation, rotation, scale }
    }

    /// A transform at `eye` whose local -Z looks at `target` with local +Y towards `up`
    /// (the glTF and camera convention).
    pub fn looking_at(eye: Vec3, target: Vec3, up: Vec3) -> Self {
        let forward = (target - eye).normalize();
        let right = forward.cross(up).normalize();
        let true_up = right.cross(forward);
        let rotation = Quat::from_mat3(&Mat3::from_cols(right, true_up, -forward)).normalize();
        Self { translation: eye, rotation, scale: Vec3::ONE }
    }

    pub fn matrix(&self) -> Mat4 {
        Mat4::from_scale_rotation_translation(self.scale, self.rotation, self.translation)
    }

    /// Interpolation for keyframes: linear translation and scale, spherical rotation.
    pub fn interpolate(&self, other: &Transform, s: f32) -> Transform {
        Transform {
            translation: self.translation.lerp(other.translation, s),
            rotation: self.rotation.slerp(other.rotation, s),
            scale: self.scale.lerp(other.scale, s),
        }
    }
}

/// Object-to-world matrix, written by [`propagate_transforms`].
#[derive(Component, Clone, Copy, Debug, PartialEq)]
pub struct GlobalTransform(pub Mat4);

impl Default for GlobalTransform {
    fn default() -> Self {
        Self(Mat4::IDENTITY)
    }
}

/// Walks the hierarchy from every root and composes parent * local.
pub fn propagate_transforms(
    roots: Query<Entity, (With<Transform>, Without<ChildOf>)>,
    locals: Query<&Transform>,
    children: Query<&Children>,
    mut globals: Query<&mut GlobalTransform>,
) {
    let mut stack: Vec<(Entity, Mat4)> = roots.iter().map(|e| (e, Mat4::IDENTITY)).collect();
    while let Some((entity, parent)) = stack.pop() {
        let Ok(local) = locals.get(entity) else { continue };
        let world = parent * local.matrix();
        if let Ok(mut global) = globals.get_mut(entity)
            && global.0 != world
        {
            global.0 = world;
        }
        if let Ok(kids) = children.get(entity) {
            stack.extend(kids.iter().map(|c| (c, world)));
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use bevy_ecs::system::RunSystemOnce;

    #[test]
    fn looking_at_points_minus_z_at_target() {
        let t = Transform::looking_at(Vec3::new(1.0, 2.0, 3.0), Vec3::new(1.0, 2.0, 0.0), Vec3::Y);
        let forward = t.rotation * Vec3::NEG_Z;
        assert!((forward - Vec3::NEG_Z).length() < 1e-5);
        let t = Transform::looking_at(Vec3::ZERO, Vec3::new(1.0, 0.0, 0.0), Vec3::Y);
        assert!((t.rotation * Vec3::NEG_Z - Vec3::X).length() < 1e-5);
        assert!((t.rotation * Vec3::Y - Vec3::Y).length() < 1e-5);
    }

    #[test]
    fn children_follow_parents() {
        let mut world = World::new();
        let parent = world
            .spawn((
                Transform::from_translation(Vec3::new(1.0, 0.0, 0.0)),
                GlobalTransform::default(),
            ))
            .id();
        let child = world
            .spawn((
                Transform::from_translation(Vec3::new(0.0, 2.0, 0.0)),
                GlobalTransform::default(),
                ChildOf(parent),
            ))
            .id();
        world.run_system_once(propagate_transforms).unwrap();
        let g = world.get::<GlobalTransform>(child).unwrap().0;
        assert!((g.transform_point3(Vec3::ZERO) - Vec3::new(1.0, 2.0, 0.0)).length() < 1e-6);
    }
}
