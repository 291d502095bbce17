//! Extract: the simulated world -> the renderer's `SceneDesc`, and what changed since the
//! last frame (so the GPU side re-uploads materials or refits the TLAS only when needed).
//!
//! The ECS queries themselves live in `sim::extract` because `sim::Simulation::scene`
//! performs them (this crate depends on `sim`, not the reverse); they are re-exported here
//! so per-frame glue has one place to look.

use render::scene::SceneDesc;

pub use sim::extract::{extract_dynamic, world_camera, world_light};

/// Which parts of the scene differ between two consecutive frames.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct SceneChanges {
    /// Meshes or textures (only on the first frame: geometry is static during a run).
    pub geometry: bool,
    /// Instance transforms, meshes or materials indices: the TLAS needs a refit or rebuild.
    pub instances: bool,
    pub materials: bool,
    pub lights: bool,
    pub camera: bool,
    pub environment: bool,
}

impl SceneChanges {
    /// Everything changed (a first frame).
    pub const ALL: SceneChanges =
        SceneChanges { geometry: true, instances: true, materials: true, lights: true, camera: true, environment: true };

    /// Compares the dynamic parts; geometry is compared by counts only (it is static).
    pub fn between(previous: &SceneDesc, next: &SceneDesc) -> SceneChanges {
        SceneChanges {
            geometry: previous.meshes.len() != next.meshes.len() || previous.textures.len() != next.textures.len(),
            instances: previous.instances != next.instances,
            materials: previous.materials != next.materials,
            lights: previous.lights != next.lights,
            camera: previous.camera != next.camera,
            environment: previous.environment != next.environment,
        }
    }

    pub fn any(&self) -> bool {
        *self != SceneChanges::default()
    }

    /// Did the world-space geometry move (TLAS refit/rebuild)?
    pub fn moved(&self) -> bool {
        self.geometry || self.instances
    }
}

/// Keeps the previous frame's dynamic scene to report [`SceneChanges`] frame by frame.
#[derive(Default)]
pub struct ChangeTracker {
    previous: Option<SceneDesc>,
}

impl ChangeTracker {
    /// Changes from the last call's scene to `scene` (everything on the first call).
    pub fn update(&mut self, scene: &SceneDesc) -> SceneChanges {
        let dynamic = SceneDesc { meshes: Vec::new(), textures: Vec::new(), ..scene.clone() };
        let changes = match &self.previous {
            None => SceneChanges::ALL,
            Some(prev) => {
                let mut c = SceneChanges::between(prev, &dynamic);
                c.geometry = false;
                c
            }
        };
        self.previous = Some(dynamic);
        changes
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::path::Path;

    fn scenario(extra: &str) -> sim::Scenario {
        sim::Scenario::from_ron(
            &format!(
                "Scenario(scene: Builtin(\"cornell_box\"), resolution: (16, 16), frames: 10, time_step: 0.1, methods: [PathTracing(spp: 1)], {extra})"
            ),
            Path::new("inline.ron"),
        )
        .unwrap()
    }

    #[test]
    fn tracker_reports_what_each_event_changed() {
        let s = scenario(
            "events: [(frame: 2, action: MoveBy(entity: \"short_box\", offset: (0.1, 0, 0))),
                      (frame: 3, action: SetMaterial(material: \"red\", base_color: (1, 0, 0))),
                      (frame: 4, action: Toggle(entity: \"ceiling_light\"))]",
        );
        let mut sim = sim::Simulation::new(&s).unwrap();
        let mut tracker = ChangeTracker::default();
        assert_eq!(tracker.update(sim.scene()), SceneChanges::ALL);
        let mut seen = Vec::new();
        for _ in 0..5 {
            sim.step();
            let c = tracker.update(sim.scene());
            assert_eq!(c.any(), sim.changed(), "tracker and simulation agree at frame {}", sim.frame());
            seen.push(c);
        }
        assert!(!seen[0].any());
        assert_eq!(seen[1], SceneChanges { instances: true, ..Default::default() });
        assert!(seen[1].moved());
        assert_eq!(seen[2], SceneChanges { materials: true, ..Default::default() });
        // Toggling an emissive mesh changes its own material's emission.
        assert_eq!(seen[3], SceneChanges { materials: true, ..Default::default() });
        assert!(!seen[4].any());
    }
}
