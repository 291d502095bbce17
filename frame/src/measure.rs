//! Measure stage: every recorded frame of every method against its previous frame (SMAPE) and
//! against the reference (FLIP, MSE, PSNR), then per region of interest.

use bevy_ecs::prelude::*;

use super::reference::References;
use super::resources::{FrameClock, MethodFrame, MethodInfo, Run};
use crate::frame_metrics;

/// The method's output as a frame to measure; the record starts with its label and counters.
pub fn prepare(
    run: Res<Run>,
    clock: Res<FrameClock>,
    mut methods: Query<(&MethodInfo, &mut MethodFrame)>,
) {
    for (info, mut m) in &mut methods {
        let Some(out) = m.output.as_ref() else { continue };
        let motion = (!out.motion.is_empty()).then_some(out.motion.as_slice());
        let current =
            frame_metrics::Frame::from_radiance(run.width, run.height, &out.radiance, motion);
        let record = crate::frame_record::FrameRecord {
            method: info.label.clone(),
            frame: clock.frame,
            cpu_ms: m.cpu_ms,
            passes: out.passes.clone(),
            clock: out.clock,
            rays: out.rays,
            shaded: out.shaded,
            stats: out.stats.clone(),
            ..Default::default()
        };
        m.current = Some(current);
        m.record = record;
    }
}

/// SMAPE against the method's previous recorded frame, plain and motion-reprojected.
pub fn smape_vs_previous(run: Res<Run>, mut methods: Query<&mut MethodFrame>) {
    for mut m in &mut methods {
        let m = &mut *m;
        let Some(current) = &m.current else { continue };
        m.smape_map = frame_metrics::smape_vs_previous(
            &mut m.record,
            current,
            m.previous.as_ref(),
            run.scenario.smape_epsilon,
        );
    }
}

/// HDR-FLIP, MSE, relative MSE and PSNR against this frame's reference, where there is one.
pub fn flip_vs_reference(references: Res<References>, mut methods: Query<&mut MethodFrame>) {
    let reference = references.current.as_ref().map(|(_, f)| f);
    for mut m in &mut methods {
        let m = &mut *m;
        let Some(current) = &m.current else { continue };
        m.flip_map = frame_metrics::error_vs_reference(&mut m.record, current, reference);
    }
}

/// Means of the FLIP and SMAPE maps over the scenario's regions of interest.
pub fn regions(run: Res<Run>, mut methods: Query<&mut MethodFrame>) {
    for mut m in &mut methods {
        let m = &mut *m;
        if m.current.is_none() {
            continue;
        }
        frame_metrics::regions(
            &mut m.record,
            &run.scenario,
            run.width,
            m.flip_map.as_deref(),
            m.smape_map.as_deref(),
        );
    }
}
