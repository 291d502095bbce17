//! A scenario's world, stepped at a fixed time step and extracted for the renderer.

use std::collections::HashMap;
use std::path::PathBuf;

use bevy_ecs::prelude::*;
use bevy_ecs::schedule::SingleThreadedExecutor;
use glam::{Quat, Vec3};
use scene::{SceneChanges, SceneDesc};

use crate::animation::{self, *};
use crate::components::{Camera, Hidden, Intensity, LightSource, MeshInstance, Name, SpawnOrder};
use crate::extract::extract_dynamic;
use crate::gltf_import::{self, GltfError};
use crate::resources::{ActiveCamera, Clock, Environment, MaterialTable, SimRng};
use crate::scenario::{
    ActionSpec, AnimationSpec, Scenario, SceneSource, WaveformSpec, find_quoted,
};
use crate::template::WorldTemplate;
use crate::transform::{GlobalTransform, Transform, propagate_transforms};

/// Why a scenario's world could not be set up.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum SimError {
    #[error("{0}")]
    Gltf(#[from] GltfError),
    #[error("{}: unknown {kind} '{name}'; expected one of: {}", place(file, *position), list(known))]
    UnknownName {
        file: PathBuf,
        position: Option<(usize, usize)>,
        kind: &'static str,
        name: String,
        known: Vec<String>,
    },
    #[error("{}: {message}", place(file, *position))]
    Invalid { file: PathBuf, position: Option<(usize, usize)>, message: String },
}

fn place(file: &std::path::Path, position: Option<(usize, usize)>) -> String {
    match position {
        Some((l, c)) => format!("{}:{l}:{c}", file.display()),
        None => file.display().to_string(),
    }
}

fn list(known: &[String]) -> String {
    const SHOWN: usize = 40;
    let mut s = known.iter().take(SHOWN).cloned().collect::<Vec<_>>().join(", ");
    if known.len() > SHOWN {
        s += &format!(", ... ({} more)", known.len() - SHOWN);
    }
    s
}

/// Maps the scenario's names to entities and materials, with errors that point into the file.
struct Names<'a> {
    scenario: &'a Scenario,
    entities: HashMap<String, Entity>,
    ordered: Vec<String>,
}

impl Names<'_> {
    fn unknown(&self, kind: &'static str, name: &str, known: Vec<String>) -> SimError {
        SimError::UnknownName {
            file: self.scenario.origin.clone(),
            position: find_quoted(&self.scenario.source, name),
            kind,
            name: name.to_string(),
            known,
        }
    }

    fn invalid(&self, name: &str, message: String) -> SimError {
        SimError::Invalid {
            file: self.scenario.origin.clone(),
            position: find_quoted(&self.scenario.source, name),
            message,
        }
    }

    fn entity(&self, name: &str) -> Result<Entity, SimError> {
        self.entities
            .get(name)
            .copied()
            .ok_or_else(|| self.unknown("entity", name, self.ordered.clone()))
    }

    fn material(&self, world: &World, name: &str) -> Result<u32, SimError> {
        let table = world.resource::<MaterialTable>();
        table.index_of(name).ok_or_else(|| self.unknown("material", name, table.names.clone()))
    }
}

/// With the random-walk reference on, every subsurface material must map to a medium
/// (scene::SubsurfaceMedium: albedo in [0, 1], positive dmfp); the error points at its override
/// in the scenario, else at `reference`.
fn check_random_walk_media(world: &World, names: &Names) -> Result<(), SimError> {
    let table = world.resource::<MaterialTable>();
    for (m, name) in table.materials.iter().zip(&table.names) {
        let Some(sss) = m.subsurface else { continue };
        if let Err(e) = scene::SubsurfaceMedium::from_albedo(m.base_color, sss.dmfp) {
            let text = &names.scenario.source;
            return Err(SimError::Invalid {
                file: names.scenario.origin.clone(),
                position: find_quoted(text, name).or_else(|| {
                    text.find("random_walk").map(|at| crate::scenario::line_col(text, at))
                }),
                message: format!("material '{name}': random-walk reference: {e}"),
            });
        }
    }
    Ok(())
}

/// The scene of the current frame as the renderer sees it, and what changed since the last.
/// [`extract_scene`] rewrites it (and marks it changed for ECS change detection) only when
/// something changed.
#[derive(Resource, Clone, Debug)]
pub struct ExtractedScene {
    pub scene: SceneDesc,
    pub changes: SceneChanges,
}

/// Simulate stage: moves the clock to the next frame (before the animation systems read it).
pub fn advance_clock(mut clock: ResMut<Clock>) {
    clock.frame += 1;
}

/// Simulate stage, in order: animations, this frame's events, transform propagation.
pub fn animation_systems() -> bevy_ecs::schedule::ScheduleConfigs<bevy_ecs::system::ScheduleSystem>
{
    (
        animation::play_clips,
        animation::rotate,
        animation::rotate_once,
        animation::keyframes,
        animation::camera_path,
        animation::flock,
        animation::flash,
        animation::apply_events,
        propagate_transforms,
    )
        .chain()
}

/// Extract stage: the world -> [`ExtractedScene`], with what changed since the last frame. The
/// resource is marked changed (ECS change detection) only when something did.
pub fn extract_scene(world: &mut World) {
    world.resource_scope(|world, mut extracted: Mut<ExtractedScene>| {
        let e = extracted.bypass_change_detection();
        let s = &mut e.scene;
        // The dynamic parts of the last frame (meshes and textures are static: not copied).
        let before = SceneDesc {
            instances: std::mem::take(&mut s.instances),
            lights: std::mem::take(&mut s.lights),
            materials: std::mem::take(&mut s.materials),
            camera: s.camera,
            environment: s.environment,
            ..Default::default()
        };
        extract_dynamic(world, s);
        e.changes = SceneChanges { geometry: false, ..SceneChanges::between(&before, s) };
        if e.changes.any() {
            extracted.set_changed();
        }
    });
}

/// The playing world of one scenario.
pub struct Simulation {
    world: World,
    schedule: Schedule,
}

impl Simulation {
    /// Loads or builds the scene, spawns it, attaches the animations and events (every name
    /// checked now, before frame 0) and sets up frame 0.
    pub fn new(scenario: &Scenario) -> Result<Simulation, SimError> {
        let template: WorldTemplate = match &scenario.scene {
            SceneSource::Builtin(name) => {
                crate::scenes::build(name).ok_or_else(|| SimError::Invalid {
                    file: scenario.origin.clone(),
                    position: find_quoted(&scenario.source, name),
                    message: format!(
                        "unknown scene '{name}'; expected one of: {}",
                        crate::scenes::names().join(", ")
                    ),
                })?
            }
            SceneSource::Gltf(path) => gltf_import::import(path)?,
        };
        let mut world = World::new();
        world.insert_resource(Clock { time_step: scenario.time_step, frame: 0 });
        world.insert_resource(SimRng::new(scenario.seed));
        template.spawn(&mut world);
        if let Some(env) = scenario.environment {
            world.insert_resource(Environment(env));
        }

        let mut names = Names { scenario, entities: HashMap::new(), ordered: Vec::new() };
        let mut named: Vec<(Option<SpawnOrder>, Entity, String)> = world
            .query::<(Entity, &Name, Option<&SpawnOrder>)>()
            .iter(&world)
            .map(|(e, n, o)| (o.copied(), e, n.as_str().to_string()))
            .collect();
        named.sort_by_key(|(o, e, _)| (*o, *e));
        let named = named.into_iter().map(|(_, e, n)| (e, n));
        for (e, n) in named {
            if !names.entities.contains_key(&n) {
                names.entities.insert(n.clone(), e);
                names.ordered.push(n);
            }
        }

        // Global transforms before anything reads them (camera baking, rest poses).
        world.run_system_cached(propagate_transforms).expect("transform propagation runs");
        if let Some(c) = &scenario.camera {
            let camera = detach_active_camera(&mut world);
            *world.get_mut::<Transform>(camera).unwrap() =
                Transform::looking_at(c.position, c.target, c.up);
            world.get_mut::<Camera>(camera).unwrap().vfov = c.vfov_degrees.to_radians();
        }

        for o in &scenario.materials {
            let index = names.material(&world, &o.material)? as usize;
            world.resource_mut::<MaterialTable>().materials[index].subsurface = o.subsurface;
        }
        if scenario.reference.random_walk {
            check_random_walk_media(&world, &names)?;
        }

        for (index, spec) in scenario.animations.iter().enumerate() {
            attach_animation(&mut world, &names, spec, index as u64, scenario.seed)?;
        }

        let mut events = Vec::new();
        for e in &scenario.events {
            let action = match &e.action {
                ActionSpec::RotateLight { light, axis, degrees } => {
                    let entity = names.entity(light)?;
                    if world.get::<LightSource>(entity).is_none() {
                        return Err(names.invalid(
                            light,
                            format!("'{light}' is not a light; expected an entity with a light"),
                        ));
                    }
                    EventAction::Rotate {
                        entity,
                        axis: checked_axis(&names, light, *axis)?,
                        angle: degrees.to_radians(),
                    }
                }
                ActionSpec::Rotate { entity, axis, degrees } => EventAction::Rotate {
                    entity: names.entity(entity)?,
                    axis: checked_axis(&names, entity, *axis)?,
                    angle: degrees.to_radians(),
                },
                ActionSpec::Toggle { entity } => {
                    let id = names.entity(entity)?;
                    ensure_emitter(&mut world, &names, entity, id)?;
                    EventAction::Toggle { entity: id }
                }
                ActionSpec::MoveTo { entity, translation } => {
                    EventAction::MoveTo { entity: names.entity(entity)?, translation: *translation }
                }
                ActionSpec::MoveBy { entity, offset } => {
                    EventAction::MoveBy { entity: names.entity(entity)?, offset: *offset }
                }
                ActionSpec::SetMaterial { material, base_color, emission, roughness, metallic } => {
                    EventAction::SetMaterial {
                        material: names.material(&world, material)?,
                        base_color: *base_color,
                        emission: *emission,
                        roughness: *roughness,
                        metallic: *metallic,
                    }
                }
            };
            events.push(ScheduledEvent { frame: e.frame, action });
        }
        world.insert_resource(ScheduledEvents(events));

        // Frame 0: the animations at time 0, then the first extraction (everything is new).
        let mut first = Schedule::default();
        first.set_executor(SingleThreadedExecutor::default());
        first.add_systems(animation_systems());
        first.run(&mut world);
        let mut scene = SceneDesc {
            meshes: template.meshes,
            textures: template.textures,
            ..Default::default()
        };
        extract_dynamic(&mut world, &mut scene);
        // A run whose frames say nothing is refused before any is rendered.
        let authored: Vec<scene::Light> =
            world.query::<&LightSource>().iter(&world).map(|l| l.0).collect();
        let problem = crate::meaningless::degenerate_geometry(&scene)
            .or_else(|| crate::meaningless::nothing_emits(scenario, &authored, &scene));
        if let Some(message) = problem {
            let text = &scenario.source;
            let key = if message.starts_with("nothing") && scenario.environment.is_some() {
                "environment"
            } else {
                "scene"
            };
            return Err(SimError::Invalid {
                file: scenario.origin.clone(),
                position: crate::meaningless::key_position(text, key),
                message,
            });
        }
        world.insert_resource(ExtractedScene { scene, changes: SceneChanges::ALL });

        let mut schedule = Schedule::default();
        schedule.set_executor(SingleThreadedExecutor::default());
        schedule.add_systems((advance_clock, animation_systems(), extract_scene).chain());
        Ok(Simulation { world, schedule })
    }

    /// The frame whose state the world holds (0 after `new`).
    pub fn frame(&self) -> u32 {
        self.world.resource::<Clock>().frame
    }

    /// Simulated time of the current frame, seconds.
    pub fn time(&self) -> f32 {
        self.world.resource::<Clock>().time()
    }

    /// Advances one fixed step: the systems of the frame's Simulate and Extract stages
    /// ([`advance_clock`], [`animation_systems`], [`extract_scene`]).
    pub fn step(&mut self) {
        self.schedule.run(&mut self.world);
    }

    /// The scene of the current frame (meshes and textures never change).
    pub fn scene(&self) -> &SceneDesc {
        &self.world.resource::<ExtractedScene>().scene
    }

    /// What the last step changed (everything after `new`).
    pub fn changes(&self) -> SceneChanges {
        self.world.resource::<ExtractedScene>().changes
    }

    /// Whether the last step changed anything the image depends on (true after `new`).
    pub fn changed(&self) -> bool {
        self.changes().any()
    }

    /// The world, to run the frame's own schedule on (its Simulate and Extract stages add
    /// [`advance_clock`], [`animation_systems`] and [`extract_scene`]).
    pub fn into_world(self) -> World {
        self.world
    }

    /// The entity with this name (the first one, if several share it).
    pub fn entity(&mut self, name: &str) -> Option<Entity> {
        let mut found: Vec<(Option<SpawnOrder>, Entity)> = self
            .world
            .query::<(Entity, &Name, Option<&SpawnOrder>)>()
            .iter(&self.world)
            .filter(|(_, n, _)| n.as_str() == name)
            .map(|(e, _, o)| (o.copied(), e))
            .collect();
        found.sort();
        found.first().map(|(_, e)| *e)
    }

    pub fn world(&self) -> &World {
        &self.world
    }

    /// For tools and tests that need to poke the world; changes show after the next `step`.
    pub fn world_mut(&mut self) -> &mut World {
        &mut self.world
    }
}

/// Makes the active camera a root with its current world placement, so overrides and
/// camera paths are in world space.
fn detach_active_camera(world: &mut World) -> Entity {
    let camera = world.resource::<ActiveCamera>().0;
    if world.get::<ChildOf>(camera).is_some() {
        let global = world.get::<GlobalTransform>(camera).unwrap().0;
        world.entity_mut(camera).remove::<ChildOf>();
        *world.get_mut::<Transform>(camera).unwrap() = Transform::from_matrix(global);
    }
    camera
}

fn checked_axis(names: &Names, who: &str, axis: Vec3) -> Result<Vec3, SimError> {
    if axis.length_squared() > 1e-12 && axis.is_finite() {
        Ok(axis.normalize())
    } else {
        Err(names
            .invalid(who, format!("rotation axis of '{who}' is zero; expected a non-zero vector")))
    }
}

/// Lights already carry an [`Intensity`]; an emissive mesh gets one here.
fn ensure_emitter(
    world: &mut World,
    names: &Names,
    name: &str,
    entity: Entity,
) -> Result<(), SimError> {
    if world.get::<Intensity>(entity).is_some() {
        return Ok(());
    }
    let emissive = world.get::<MeshInstance>(entity).is_some_and(|m| {
        world.resource::<MaterialTable>().materials[m.material as usize].emission.max_element()
            > 0.0
    });
    if !emissive {
        return Err(names.invalid(
            name,
            format!(
                "'{name}' is neither a light nor an emissive mesh; expected something that emits"
            ),
        ));
    }
    world.entity_mut(entity).insert(Intensity::default());
    Ok(())
}

fn attach_animation(
    world: &mut World,
    names: &Names,
    spec: &AnimationSpec,
    index: u64,
    seed: u64,
) -> Result<(), SimError> {
    match spec {
        AnimationSpec::Rotate { entity, axis, degrees_per_second } => {
            let e = names.entity(entity)?;
            let axis = checked_axis(names, entity, *axis)?;
            world.entity_mut(e).insert(Rotate { axis, speed: degrees_per_second.to_radians() });
        }
        AnimationSpec::RotateOnce { entity, axis, degrees, frame } => {
            let e = names.entity(entity)?;
            let axis = checked_axis(names, entity, *axis)?;
            world.entity_mut(e).insert(RotateOnce {
                axis,
                angle: degrees.to_radians(),
                frame: *frame,
            });
        }
        AnimationSpec::Flash { entity, waveform } => {
            let e = names.entity(entity)?;
            ensure_emitter(world, names, entity, e)?;
            let waveform = match *waveform {
                WaveformSpec::Sine { frequency } => Waveform::Sine { frequency },
                WaveformSpec::Square { period } if period > 0.0 => Waveform::Square { period },
                WaveformSpec::Square { period } => {
                    return Err(names
                        .invalid(entity, format!("square period {period}; expected > 0 seconds")));
                }
                WaveformSpec::Strobe { probability } => Waveform::Strobe { probability },
            };
            world.entity_mut(e).insert(Flash { waveform, stream: index });
        }
        AnimationSpec::Boids {
            prototype,
            count,
            bounds_min,
            bounds_max,
            separation,
            view_radius,
            max_speed,
            min_speed,
        } => {
            let proto = names.entity(prototype)?;
            let Some(mesh) = world.get::<MeshInstance>(proto).copied() else {
                return Err(names.invalid(
                    prototype,
                    format!("'{prototype}' has no mesh; expected an entity with a mesh to copy"),
                ));
            };
            let d = FlockParams::default();
            let params = FlockParams {
                bounds_min: bounds_min.unwrap_or(d.bounds_min),
                bounds_max: bounds_max.unwrap_or(d.bounds_max),
                separation: separation.unwrap_or(d.separation),
                view_radius: view_radius.unwrap_or(d.view_radius),
                max_speed: max_speed.unwrap_or(d.max_speed),
                min_speed: min_speed.unwrap_or(d.min_speed),
                ..d
            };
            if !params.bounds_min.cmplt(params.bounds_max).all() {
                return Err(names.invalid(
                    prototype,
                    "boids bounds_min must be below bounds_max on every axis".into(),
                ));
            }
            let scale = world.get::<Transform>(proto).map_or(Vec3::ONE, |t| t.scale);
            world.entity_mut(proto).insert((Flock { params }, Hidden));
            let mut rng = crate::rng::stream(seed, index);
            let first =
                world.query::<&SpawnOrder>().iter(world).map(|o| o.0 + 1).max().unwrap_or(0);
            for (i, (p, v)) in initial_boids(&params, *count, &mut rng).into_iter().enumerate() {
                world.spawn((
                    Name::new(format!("{prototype}_{i}")),
                    Transform::from_trs(p, animation::boids::heading(v), scale),
                    GlobalTransform::default(),
                    mesh,
                    Boid { flock: proto, index: i as u32, velocity: v },
                    SpawnOrder(first + i as u32),
                ));
            }
        }
        AnimationSpec::Keyframes { entity, keys, repeat } => {
            let e = names.entity(entity)?;
            if keys.is_empty() {
                return Err(names.invalid(
                    entity,
                    format!("keyframes of '{entity}' are empty; expected at least one key"),
                ));
            }
            let rest = *world.get::<Transform>(e).unwrap();
            let mut keys: Vec<Keyframe> = keys
                .iter()
                .map(|k| Keyframe {
                    frame: k.frame,
                    transform: Transform {
                        translation: k.translation.unwrap_or(rest.translation),
                        rotation: k.rotation.as_ref().map_or(rest.rotation, |r| {
                            Quat::from_axis_angle(r.axis.normalize(), r.degrees.to_radians())
                        }),
                        scale: k.scale.unwrap_or(rest.scale),
                    },
                })
                .collect();
            keys.sort_by(|a, b| a.frame.total_cmp(&b.frame));
            world.entity_mut(e).insert(Keyframes { keys, repeat: *repeat });
        }
        AnimationSpec::CameraPath { keys, repeat } => {
            if keys.is_empty() {
                return Err(SimError::Invalid {
                    file: names.scenario.origin.clone(),
                    position: None,
                    message: "camera path has no keys; expected at least one".into(),
                });
            }
            let camera = detach_active_camera(world);
            let vfov = world.get::<Camera>(camera).unwrap().vfov;
            let mut keys: Vec<CameraKey> = keys
                .iter()
                .map(|k| CameraKey {
                    frame: k.frame,
                    position: k.position,
                    target: k.target,
                    vfov: k.vfov_degrees.map_or(vfov, f32::to_radians),
                })
                .collect();
            keys.sort_by(|a, b| a.frame.total_cmp(&b.frame));
            world.entity_mut(camera).insert(CameraPath { keys, repeat: *repeat });
        }
    }
    Ok(())
}
