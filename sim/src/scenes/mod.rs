//! Built-in procedural scenes, addressable by name. Every scene names the entities that
//! scenarios animate.

pub mod cornell_box;
pub mod corridor;
pub mod courtyard;
pub mod door_gap;
pub mod geometry;
pub mod hairball;
pub mod rotating_cone;
pub mod sss_sphere;

use crate::template::WorldTemplate;

/// A built-in scene: its name, a one-line description and its generator.
pub struct BuiltinScene {
    pub name: &'static str,
    pub description: &'static str,
    pub build: fn() -> WorldTemplate,
}

pub const SCENES: &[BuiltinScene] = &[
    BuiltinScene {
        name: "cornell_box",
        description: "Classic Cornell box: red/green walls, ceiling area light, tall and short boxes",
        build: cornell_box::build,
    },
    BuiltinScene {
        name: "corridor",
        description: "Winding corridor lit only from its far end: light arrives after many bounces",
        build: corridor::build,
    },
    BuiltinScene {
        name: "door_gap",
        description: "Dark room lit through the narrow gap of a nearly closed door (hinged, animatable)",
        build: door_gap::build,
    },
    BuiltinScene {
        name: "courtyard",
        description: "Open courtyard under a dominant directional sun, with pillars and a lantern",
        build: courtyard::build,
    },
    BuiltinScene {
        name: "hairball",
        description: "Ball of a few thousand thin strands (~36k triangles) under sky and key light",
        build: hairball::build,
    },
    BuiltinScene {
        name: "rotating_cone",
        description: "A cone lying on a floor on a turntable, lit by a point light",
        build: rotating_cone::build,
    },
    BuiltinScene {
        name: "sss_sphere",
        description: "A skin sphere under a point light with a bar's shadow edge and two candles (subsurface tests)",
        build: sss_sphere::build,
    },
];

/// Names of the built-in scenes.
pub fn names() -> Vec<&'static str> {
    SCENES.iter().map(|s| s.name).collect()
}

/// One-line description of a built-in scene.
pub fn describe(name: &str) -> Option<&'static str> {
    SCENES.iter().find(|s| s.name == name).map(|s| s.description)
}

/// Builds a built-in scene by name.
pub fn build(name: &str) -> Option<WorldTemplate> {
    SCENES.iter().find(|s| s.name == name).map(|s| (s.build)())
}

/// What scenarios can name in a built-in scene: its entities (nodes, in spawn order), its lights
/// (analytic lights, emissive meshes and the sky) and its materials.
#[derive(Clone, Debug, PartialEq)]
pub struct Inventory {
    pub entities: Vec<String>,
    /// Each light as `NAME (KIND)`.
    pub lights: Vec<String>,
    pub materials: Vec<String>,
}

/// The inventory of a scene as built.
pub fn inventory(t: &WorldTemplate) -> Inventory {
    let mut lights = Vec::new();
    for n in &t.nodes {
        let kind = match (n.light, n.mesh) {
            (Some(scene::Light::Point { .. }), _) => "point light",
            (Some(scene::Light::Spot { .. }), _) => "spot light",
            (Some(scene::Light::Directional { .. }), _) => "directional light",
            (None, Some(m))
                if t.materials.materials[m.material as usize].emission.max_element() > 0.0 =>
            {
                "emissive mesh"
            }
            _ => continue,
        };
        lights.push(format!("{} ({kind})", n.name));
    }
    if t.environment.max_element() > 0.0 {
        lights.push("environment (constant sky radiance)".into());
    }
    Inventory {
        entities: t.nodes.iter().map(|n| n.name.clone()).collect(),
        lights,
        materials: t.materials.names.iter().filter(|n| !n.is_empty()).cloned().collect(),
    }
}

/// `flicker scenes`: every built-in scene with its description, entities, lights and materials.
pub fn listing() -> String {
    let mut out = String::new();
    for s in SCENES {
        let inv = inventory(&(s.build)());
        out.push_str(&format!("{}: {}\n", s.name, s.description));
        out.push_str(&format!("  entities:  {}\n", inv.entities.join(", ")));
        out.push_str(&format!("  lights:    {}\n", inv.lights.join(", ")));
        out.push_str(&format!("  materials: {}\n", inv.materials.join(", ")));
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn listing_names_every_entity_light_and_material() {
        let text = listing();
        for s in SCENES {
            // Each scene's block: the indented lines under its header.
            let header = format!("{}: {}", s.name, s.description);
            let block: Vec<&str> = text
                .lines()
                .skip_while(|l| *l != header)
                .skip(1)
                .take_while(|l| l.starts_with("  "))
                .collect();
            let block = block.join("\n");
            let t = (s.build)();
            let line = |key: &str| {
                block
                    .lines()
                    .find_map(|l| l.trim_start().strip_prefix(key))
                    .unwrap_or_else(|| panic!("{}: no `{key}` line in\n{block}", s.name))
                    .trim()
                    .split(", ")
                    .map(String::from)
                    .collect::<Vec<_>>()
            };
            let nodes: Vec<String> = t.nodes.iter().map(|n| n.name.clone()).collect();
            assert_eq!(line("entities:"), nodes, "{}", s.name);
            let lights = line("lights:");
            for n in &t.nodes {
                let lit = n.light.is_some()
                    || n.mesh.is_some_and(|m| {
                        t.materials.materials[m.material as usize].emission.max_element() > 0.0
                    });
                let listed = lights.iter().any(|l| l.starts_with(&format!("{} (", n.name)));
                assert_eq!(lit, listed, "{}: light {} in {lights:?}", s.name, n.name);
            }
            assert_eq!(
                t.environment.max_element() > 0.0,
                lights.iter().any(|l| l.starts_with("environment")),
                "{}: sky",
                s.name
            );
            for m in t.materials.names.iter().filter(|m| !m.is_empty()) {
                assert!(line("materials:").contains(m), "{}: material {m}", s.name);
            }
        }
    }

    #[test]
    fn every_scene_builds_with_light_camera_and_valid_indices() {
        for s in SCENES {
            let t = (s.build)();
            assert!(t.nodes.iter().any(|n| n.camera.is_some()), "{}: no camera", s.name);
            let emissive =
                t.nodes.iter().filter_map(|n| n.mesh).any(|m| {
                    t.materials.materials[m.material as usize].emission.max_element() > 0.0
                });
            assert!(
                emissive
                    || t.nodes.iter().any(|n| n.light.is_some())
                    || t.environment.max_element() > 0.0,
                "{}: unlit",
                s.name
            );
            for n in &t.nodes {
                if let Some(m) = n.mesh {
                    assert!(
                        (m.mesh as usize) < t.meshes.len()
                            && (m.material as usize) < t.materials.materials.len(),
                        "{}: bad node {}",
                        s.name,
                        n.name
                    );
                }
            }
            for m in &t.meshes {
                assert!(!m.indices.is_empty(), "{}: empty mesh {}", s.name, m.name);
                assert!(
                    m.indices.iter().flatten().all(|&i| (i as usize) < m.positions.len()),
                    "{}: mesh {} index out of range",
                    s.name,
                    m.name
                );
            }
            let mut names: Vec<&str> = t.nodes.iter().map(|n| n.name.as_str()).collect();
            names.sort();
            let before = names.len();
            names.dedup();
            assert_eq!(before, names.len(), "{}: duplicate node names", s.name);
        }
    }
}
