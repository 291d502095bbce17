//! Record stage: images of the frame (methods, their extra images, the reference), the frames.csv
//! rows, and the hand-over of this frame to the next.

use bevy_ecs::prelude::*;

use super::reference::References;
use super::resources::{FrameClock, MethodFrame, MethodInfo, Progress, Run, RunOutput};
use super::stage::failed;
use crate::run_folder::MOTION;
use crate::{frame_record, output};

/// The reference's EXR and PNG.
pub fn write_reference(
    run: Res<Run>,
    clock: Res<FrameClock>,
    out: Res<RunOutput>,
    references: Res<References>,
) -> Result {
    let Some((pixels, _)) = &references.current else { return Ok(()) };
    if clock.frame < out.replay_until {
        return Ok(());
    }
    let (w, h) = (run.width, run.height);
    output::write_exr(&out.folder.reference(clock.frame, "exr"), w, h, pixels).map_err(failed)?;
    output::write_png(&out.folder.reference(clock.frame, "png"), w, h, pixels, 1.0)
        .map_err(failed)?;
    Ok(())
}

/// Each method's EXR and PNG, its motion vectors (`frames/METHOD/motion/NNNN.exr`: R, G = pixels
/// from this frame to the previous, for the report's viewer) and its extra images
/// (`frames/METHOD/NAME/NNNN.png`).
pub fn write_method_images(
    run: Res<Run>,
    clock: Res<FrameClock>,
    out: Res<RunOutput>,
    methods: Query<(&MethodInfo, &MethodFrame)>,
) -> Result {
    let (w, h, frame) = (run.width, run.height, clock.frame);
    if frame < out.replay_until {
        return Ok(());
    }
    let folder = &out.folder;
    for (info, m) in &methods {
        let Some(o) = &m.output else { continue };
        let label = &info.label;
        output::write_exr(&folder.frame(label, frame, "exr"), w, h, &o.radiance).map_err(failed)?;
        output::write_png(&folder.frame(label, frame, "png"), w, h, &o.radiance, 1.0)
            .map_err(failed)?;
        if !o.motion.is_empty() {
            let motion: Vec<[f32; 4]> =
                o.motion.iter().map(|&[dx, dy]| [dx, dy, 0.0, 1.0]).collect();
            output::write_exr(&folder.method_image(label, MOTION, frame, "exr"), w, h, &motion)
                .map_err(failed)?;
        }
        for image in &o.images {
            if image.hdr {
                output::write_exr(
                    &folder.method_image(label, &image.name, frame, "exr"),
                    w,
                    h,
                    &image.pixels,
                )
                .map_err(failed)?;
                output::write_png(
                    &folder.method_image(label, &image.name, frame, "png"),
                    w,
                    h,
                    &image.pixels,
                    1.0,
                )
                .map_err(failed)?;
            } else {
                output::write_png_linear(
                    &folder.method_image(label, &image.name, frame, "png"),
                    w,
                    h,
                    &image.pixels,
                )
                .map_err(failed)?;
            }
        }
    }
    Ok(())
}

/// Appends the frame's rows (in the scenario's method order) and rewrites frames.csv, so an
/// interrupted run still has a complete table of what it did.
pub fn write_frames_csv(
    clock: Res<FrameClock>,
    mut out: ResMut<RunOutput>,
    methods: Query<(&MethodInfo, &MethodFrame)>,
) -> Result {
    let mut rows: Vec<(usize, frame_record::FrameRecord)> = methods
        .iter()
        .filter(|(_, m)| m.current.is_some())
        .map(|(info, m)| (info.index, m.record.clone()))
        .collect();
    rows.sort_by_key(|(i, _)| *i);
    out.records.extend(rows.into_iter().map(|(_, r)| r));
    if clock.frame < out.replay_until {
        return Ok(());
    }
    let path = out.folder.frames_csv();
    output::write_text(&path, &frame_record::to_csv(&out.records)).map_err(failed)
}

/// This frame becomes the previous one; the per-frame state is cleared for the next.
pub fn end_frame(
    clock: Res<FrameClock>,
    progress: Res<Progress>,
    mut methods: Query<&mut MethodFrame>,
) {
    for mut m in &mut methods {
        let m = &mut *m;
        if clock.recorded && m.current.is_some() {
            m.previous = m.current.take();
        }
        m.output = None;
        m.current = None;
        m.cpu_ms = 0.0;
        m.smape_map = None;
        m.flip_map = None;
    }
    progress.0.inc(1);
}
