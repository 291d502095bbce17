//! Scripted events fired at a given frame, with entities and materials already resolved.

use bevy_ecs::prelude::*;
use glam::Vec3;

use crate::components::Intensity;
use crate::resources::{Clock, MaterialTable};
use crate::transform::Transform;

#[derive(Clone, Debug, PartialEq)]
pub enum EventAction {
    /// Rotate the entity (a light's entity rotates the light) by `angle` radians.
    Rotate {
        entity: Entity,
        axis: Vec3,
        angle: f32,
    },
    /// Switch a light or emissive mesh on/off.
    Toggle {
        entity: Entity,
    },
    MoveTo {
        entity: Entity,
        translation: Vec3,
    },
    MoveBy {
        entity: Entity,
        offset: Vec3,
    },
    /// Overwrite some fields of a material.
    SetMaterial {
        material: u32,
        base_color: Option<Vec3>,
        emission: Option<Vec3>,
        roughness: Option<f32>,
        metallic: Option<f32>,
    },
}

#[derive(Clone, Debug, PartialEq)]
pub struct ScheduledEvent {
    pub frame: u32,
    pub action: EventAction,
}

/// Every event of the scenario, in file order (events at one frame fire in that order).
#[derive(Resource, Clone, Debug, Default, PartialEq)]
pub struct ScheduledEvents(pub Vec<ScheduledEvent>);

pub fn apply_events(
    clock: Res<Clock>,
    events: Res<ScheduledEvents>,
    mut materials: ResMut<MaterialTable>,
    mut transforms: Query<&mut Transform>,
    mut intensities: Query<&mut Intensity>,
) {
    for event in events.0.iter().filter(|e| e.frame == clock.frame) {
        match event.action {
            EventAction::Rotate { entity, axis, angle } => {
                if let Ok(mut t) = transforms.get_mut(entity) {
                    super::rotate::turn(&mut t, axis, angle);
                }
            }
            EventAction::Toggle { entity } => {
                if let Ok(mut i) = intensities.get_mut(entity) {
                    i.on = !i.on;
                }
            }
            EventAction::MoveTo { entity, translation } => {
                if let Ok(mut t) = transforms.get_mut(entity) {
                    t.translation = translation;
                }
            }
            EventAction::MoveBy { entity, offset } => {
                if let Ok(mut t) = transforms.get_mut(entity) {
                    t.translation += offset;
                }
            }
            EventAction::SetMaterial { material, base_color, emission, roughness, metallic } => {
                let m = &mut materials.materials[material as usize];
                if let Some(c) = base_color {
                    m.base_color = c;
                }
                if let Some(e) = emission {
                    m.emission = e;
                }
                if let Some(r) = roughness {
                    m.roughness = r;
                }
                if let Some(x) = metallic {
                    m.metallic = x;
                }
            }
        }
    }
}
