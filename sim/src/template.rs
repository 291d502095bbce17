//! A scene as loaded (from glTF or a built-in generator), before it becomes ECS entities.

use bevy_ecs::prelude::*;
use glam::Vec3;
use scene::{Light, Material, Mesh, Texture};

use crate::animation::{CameraClip, LightClip, MaterialClips, NodeClip};
use crate::components::{Camera, Intensity, LightSource, MeshInstance, Name, SpawnOrder};
use crate::resources::{ActiveCamera, Environment, MaterialTable};
use crate::transform::{GlobalTransform, Transform};

/// One node of the scene graph.
#[derive(Clone, Debug, PartialEq)]
pub struct NodeTemplate {
    pub name: String,
    /// Index of the parent node; parents come before their children.
    pub parent: Option<usize>,
    pub transform: Transform,
    pub mesh: Option<MeshInstance>,
    pub light: Option<Light>,
    /// Vertical field of view of a camera on this node.
    pub camera: Option<f32>,
    /// glTF animation tracks of this node's transform, light and camera.
    pub clip: Option<NodeClip>,
    pub light_clip: Option<LightClip>,
    pub camera_clip: Option<CameraClip>,
}

impl NodeTemplate {
    pub fn new(name: impl Into<String>, transform: Transform) -> Self {
        Self {
            name: name.into(),
            parent: None,
            transform,
            mesh: None,
            light: None,
            camera: None,
            clip: None,
            light_clip: None,
            camera_clip: None,
        }
    }
}

/// Geometry, materials and nodes; the static part (meshes, textures) goes to the renderer
/// once, the nodes become entities.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct WorldTemplate {
    pub meshes: Vec<Mesh>,
    pub textures: Vec<Texture>,
    pub materials: MaterialTable,
    pub nodes: Vec<NodeTemplate>,
    pub environment: Vec3,
    /// glTF animation tracks of material factors.
    pub material_clips: MaterialClips,
}

impl WorldTemplate {
    pub fn add_mesh(&mut self, mesh: Mesh) -> u32 {
        self.meshes.push(mesh);
        (self.meshes.len() - 1) as u32
    }

    pub fn add_material(&mut self, name: &str, material: Material) -> u32 {
        self.materials.push(name, material)
    }

    pub fn add_node(&mut self, node: NodeTemplate) -> usize {
        if let Some(p) = node.parent {
            assert!(p < self.nodes.len(), "parent of node '{}' must be added first", node.name);
        }
        self.nodes.push(node);
        self.nodes.len() - 1
    }

    /// A node showing `mesh` with `material`.
    pub fn add_object(
        &mut self,
        name: &str,
        mesh: u32,
        material: u32,
        transform: Transform,
    ) -> usize {
        let mut node = NodeTemplate::new(name, transform);
        node.mesh = Some(MeshInstance { mesh, material });
        self.add_node(node)
    }

    /// A light node; point and spot positions move into the node's translation so that
    /// rotating the node turns the light in place.
    pub fn add_light(&mut self, name: &str, light: Light) -> usize {
        let (transform, light) = match light {
            Light::Point { position, intensity } => (
                Transform::from_translation(position),
                Light::Point { position: Vec3::ZERO, intensity },
            ),
            Light::Spot { position, direction, intensity, inner_angle, outer_angle } => (
                Transform::from_translation(position),
                Light::Spot {
                    position: Vec3::ZERO,
                    direction,
                    intensity,
                    inner_angle,
                    outer_angle,
                },
            ),
            directional => (Transform::IDENTITY, directional),
        };
        let mut node = NodeTemplate::new(name, transform);
        node.light = Some(light);
        self.add_node(node)
    }

    pub fn add_camera(&mut self, name: &str, eye: Vec3, target: Vec3, vfov_degrees: f32) -> usize {
        let mut node = NodeTemplate::new(name, Transform::looking_at(eye, target, Vec3::Y));
        node.camera = Some(vfov_degrees.to_radians());
        self.add_node(node)
    }

    /// Spawns every node; the first camera becomes the active one (a default camera is
    /// added when there is none).
    pub fn spawn(&self, world: &mut World) -> Vec<Entity> {
        world.insert_resource(self.materials.clone());
        world.insert_resource(Environment(self.environment));
        world.insert_resource(self.material_clips.clone());
        let mut entities: Vec<Entity> = Vec::with_capacity(self.nodes.len());
        let mut active = None;
        for (order, node) in self.nodes.iter().enumerate() {
            let mut e = world.spawn((
                Name::new(node.name.clone()),
                node.transform,
                GlobalTransform::default(),
                SpawnOrder(order as u32),
            ));
            if let Some(p) = node.parent {
                e.insert(ChildOf(entities[p]));
            }
            if let Some(mesh) = node.mesh {
                e.insert(mesh);
            }
            if let Some(light) = node.light {
                e.insert((LightSource(light), Intensity::default()));
            }
            if let Some(clip) = &node.clip {
                e.insert(clip.clone());
            }
            if let Some(clip) = &node.light_clip {
                e.insert(clip.clone());
            }
            if let Some(clip) = &node.camera_clip {
                e.insert(clip.clone());
            }
            if let Some(vfov) = node.camera {
                e.insert(Camera { vfov });
                active.get_or_insert(e.id());
            }
            entities.push(e.id());
        }
        let camera = active.unwrap_or_else(|| {
            let c = scene::Camera::default();
            world
                .spawn((
                    Name::new("camera"),
                    Transform::looking_at(c.position, c.target, c.up),
                    GlobalTransform::default(),
                    Camera { vfov: c.vfov },
                    SpawnOrder(self.nodes.len() as u32),
                ))
                .id()
        });
        world.insert_resource(ActiveCamera(camera));
        entities
    }
}
