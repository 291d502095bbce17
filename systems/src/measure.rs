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
    pub fn from_radiance(width: u32, height: u32, rgba: &[[f32; 4]], motion: Option<&[[f32; 2]]>) -> Self {
        let rgb = rgba.iter().map(|p| [p[0], p[1], p[2]]).collect();
        Self { image: Image::new(width, height, rgb), motion: motion.map(|m| m.to_vec()) }
    }
}

/// Measures `current` against the method's `previous` frame and the `reference` where given.
pub fn record(current: &Frame, previous: Option<&Frame>, reference: Option<&Frame>, scenario: &Scenario) -> FrameRecord {
    let eps = scenario.smape_epsilon;
    let regions: Vec<Region> = scenario
        .regions
        .iter()
        .map(|r| Region { name: r.name.clone(), x: r.x, y: r.y, width: r.width, height: r.height })
        .collect();
    let width = current.image.width;
    let mut rec = FrameRecord::default();
    let smape = previous.map(|prev| metrics::smape(&current.image, &prev.image, eps));
    if let Some(s) = &smape {
        rec.smape = Some(s.mean);
    }
    if let (Some(prev), Some(motion)) = (previous, &current.motion) {
        let s = metrics::smape_reprojected(&current.image, &prev.image, motion, eps);
        rec.smape_reprojected = Some(s.mean);
        rec.disoccluded = Some(s.disoccluded_count);
    }
    let flip = reference.map(|r| {
        rec.mse = Some(metrics::mse(&r.image, &current.image));
        rec.rel_mse = Some(metrics::relative_mse(&r.image, &current.image));
        rec.psnr = Some(metrics::psnr(&r.image, &current.image));
        metrics::flip_hdr(&r.image, &current.image, metrics::DEFAULT_PPD)
    });
    rec.flip = flip.as_ref().map(|f| f.mean);
    rec.regions = regions
        .iter()
        .map(|r| {
            let f = flip.as_ref().and_then(|f| r.mean_of(&f.map, width));
            let s = smape.as_ref().and_then(|s| r.mean_of(&s.map, width));
            (r.name.clone(), f, s)
        })
        .collect();
    rec
}
