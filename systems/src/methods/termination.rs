//! Path tracing terminated into a hashed radiance cache by variance trading
//! (render::termination, ../shared/seeds/variance-trading-termination.txt): one system per
//! frame runs the cache's passes (propagation, fold, the tracer with the rule's decision, the
//! vertex store) and reports the image, the pass times (tc_trace and tc_propagate separately)
//! and the mean path length (`path_length`, vertices per path counted on the GPU), with the
//! per-pixel path length as the image `path_length` (the paper's Fig. 11).

use std::time::Instant;

use anyhow::Result;
use bevy_ecs::prelude::*;
use render::termination::TerminationCache;

pub use render::termination::TerminationSettings;

use super::{MethodImage, MethodOutput, MethodPlugin};
use crate::frame::{
    FrameClock, GpuDevice, GpuScene, MethodFrame, MethodInfo, Run, Stage, method_failed,
};

/// `termination_vb_0.1`, `termination_mse_100`, ...
pub fn label(s: &TerminationSettings) -> String {
    format!("termination_{}", s.rule.label())
}

#[derive(Component)]
pub struct TerminationState {
    cache: TerminationCache,
}

pub struct Plugin;

impl MethodPlugin for Plugin {
    type Settings = TerminationSettings;
    const NAME: &'static str = "Termination";

    fn label(settings: &TerminationSettings) -> String {
        label(settings)
    }

    fn spp(_settings: &TerminationSettings) -> f64 {
        1.0
    }

    fn temporal_window(_settings: &TerminationSettings) -> Option<f64> {
        None
    }

    fn add_systems(schedule: &mut Schedule) {
        schedule.add_systems(render.in_set(Stage::Render));
    }

    fn spawn(world: &mut World, entity: Entity, settings: &TerminationSettings) -> Result<()> {
        let (gpu, gpu_scene) = (&world.resource::<GpuDevice>().0, &world.resource::<GpuScene>().0);
        // Validates the settings and checks the cache's buffers against the adapter's limits.
        let cache = TerminationCache::new(gpu, gpu_scene, *settings)?;
        world.entity_mut(entity).insert(TerminationState { cache });
        Ok(())
    }
}

/// The cache's passes and the frame's image (one path per pixel).
pub fn render(
    gpu: Res<GpuDevice>,
    gpu_scene: Res<GpuScene>,
    run: Res<Run>,
    clock: Res<FrameClock>,
    scene: Res<sim::ExtractedScene>,
    mut methods: Query<(&mut TerminationState, &MethodInfo, &mut MethodFrame)>,
) -> Result<(), BevyError> {
    for (mut state, info, mut frame) in &mut methods {
        let start = Instant::now();
        let out = state
            .cache
            .render(&gpu.0, &gpu_scene.0, &scene.scene.camera, run.scenario.seed, clock.global)
            .map_err(|e| method_failed(&info.label, clock.global, e))?;
        let s = out.stats;
        frame.output = Some(MethodOutput {
            stats: vec![
                ("path_length".into(), out.mean_path_length),
                ("cache_records".into(), s.filled as f64),
                ("cache_mean".into(), out.cache.mean),
                ("cache_variance".into(), out.cache.variance),
                ("cache_bias2".into(), out.cache.bias2),
                ("cache_bytes".into(), state.cache.cache_bytes() as f64),
                ("cache_unknown_vertices".into(), s.unknown as f64),
                ("cache_propagated_vertices".into(), s.propagated as f64),
                ("cache_insert_failures".into(), s.insert_failures as f64),
            ],
            // The paper's Fig. 11: vertices of each pixel's path (grey value = path length; the
            // EXR holds the exact values).
            images: vec![MethodImage {
                name: "path_length".into(),
                pixels: out.path_length.iter().map(|&l| [l, l, l, 1.0]).collect(),
                hdr: true,
            }],
            ..MethodOutput::timed(out.radiance, out.motion, &out.timings, out.rays, out.shaded)
        });
        frame.add_cpu(start);
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::super::Method;
    use render::termination::TerminationRule;

    #[test]
    fn scenario_text_parses_with_the_paper_defaults_and_refuses_unknown_fields() {
        let m = Method::parse("Termination(rule: MseMinimisation(s: 100.0))").unwrap();
        assert_eq!(m.label(), "termination_mse_100");
        let s =
            m.spec.get::<render::termination::TerminationSettings>().expect("Termination settings");
        assert_eq!(
            s.rule,
            TerminationRule::MseMinimisation { s: 100.0, margin: 1.1, bias_clamp: 0.1 }
        );
        assert_eq!((s.store_probability, s.survival), (0.01, 1.0));
        let e = Method::parse("Termination(rule: VarianceBounding(t: 0.1, tt: 1.0))").unwrap_err();
        assert!(e.contains("tt"), "{e}");
        let e =
            Method::parse("Termination(rule: VarianceBounding(t: 0.1), samples: 4)").unwrap_err();
        assert!(e.contains("samples"), "{e}");
    }
}
