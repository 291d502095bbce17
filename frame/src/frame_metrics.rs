//! Per-frame measurements of one method: flicker against its own previous frame (SMAPE, plain
//! and motion-reprojected) and error against the reference (HDR-FLIP, MSE, relative MSE, PSNR),
//! on the whole image and on the scenario's regions of interest.

use metrics::{Image, Region};
use sim::Scenario;

use crate::frame_record::FrameRecord;

/// A frame ready to measure: linear RGB plus its motion vectors (methods only; references
/// have none).
#[derive(Clone)]
pub struct Frame {
    pub image: Image,
    pub motion: Option<Vec<[f32; 2]>>,
}

impl Frame {
    pub fn from_radiance(
        width: u32,
        height: u32,
        rgba: &[[f32; 4]],
        motion: Option<&[[f32; 2]]>,
    ) -> Self {
        let rgb = rgba.iter().map(|p| [p[0], p[1], p[2]]).collect();
        Self { image: Image::new(width, height, rgb), motion: motion.map(|m| m.to_vec()) }
    }
}

/// Flicker: SMAPE of `current` against the method's `previous` frame, plain and reprojected
/// along `current`'s motion. Returns the per-pixel map (for regions).
pub fn smape_vs_previous(
    rec: &mut FrameRecord,
    current: &Frame,
    previous: Option<&Frame>,
    eps: f32,
) -> Option<Vec<f32>> {
    let prev = previous?;
    let smape = metrics::smape(&current.image, &prev.image, eps);
    rec.smape = Some(smape.mean);
    if let Some(motion) = &current.motion {
        let s = metrics::smape_reprojected(&current.image, &prev.image, motion, eps);
        rec.smape_reprojected = Some(s.mean);
        rec.disoccluded = Some(s.disoccluded_count);
    }
    Some(smape.map)
}

/// Error against the reference: HDR-FLIP, MSE, relative MSE, PSNR. Returns the FLIP map.
pub fn error_vs_reference(
    rec: &mut FrameRecord,
    current: &Frame,
    reference: Option<&Frame>,
) -> Option<Vec<f32>> {
    let r = reference?;
    rec.mse = Some(metrics::mse(&r.image, &current.image));
    rec.rel_mse = Some(metrics::relative_mse(&r.image, &current.image));
    rec.psnr = Some(metrics::psnr(&r.image, &current.image));
    let flip = metrics::flip_hdr(&r.image, &current.image, metrics::DEFAULT_PPD);
    rec.flip = Some(flip.mean);
    Some(flip.map)
}

/// Per region of interest: the means of the FLIP and SMAPE maps inside it.
pub fn regions(
    rec: &mut FrameRecord,
    scenario: &Scenario,
    width: u32,
    flip: Option<&[f32]>,
    smape: Option<&[f32]>,
) {
    rec.regions = scenario
        .regions
        .iter()
        .map(|r| {
            let r =
                Region { name: r.name.clone(), x: r.x, y: r.y, width: r.width, height: r.height };
            let f = flip.and_then(|f| r.mean_of(f, width));
            let s = smape.and_then(|s| r.mean_of(s, width));
            (r.name.clone(), f, s)
        })
        .collect();
}

/// Every measurement of `current` at once: [`smape_vs_previous`], [`error_vs_reference`],
/// [`regions`] (the frame's Measure stage runs them as separate systems).
pub fn record(
    current: &Frame,
    previous: Option<&Frame>,
    reference: Option<&Frame>,
    scenario: &Scenario,
) -> FrameRecord {
    let mut rec = FrameRecord::default();
    let smape = smape_vs_previous(&mut rec, current, previous, scenario.smape_epsilon);
    let flip = error_vs_reference(&mut rec, current, reference);
    regions(&mut rec, scenario, current.image.width, flip.as_deref(), smape.as_deref());
    rec
}
