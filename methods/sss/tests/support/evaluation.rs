//! Table 7.3's measures for a run of the pass: mean samples per SSS pixel, PSNR of the
//! scattered luminance against a reference, frame-to-frame SMAPE, and the per-pixel mean count.

use sss::psnr_against::psnr_luminance;
use sss::sampling::luminance;
use sss::{PixelResult, SssFrame};

/// What one variant's run measured.
#[derive(Clone, Debug, Default)]
pub struct RunMeasures {
    /// Mean count over SSS pixels and frames.
    pub mean_spp: f64,
    /// Mean over the measured frames of each frame's PSNR (dB).
    pub psnr_db: f64,
    /// Mean over frames 1.. of the SMAPE between consecutive frames (SSS pixels).
    pub smape: f64,
    /// Per pixel, the mean count over the run.
    pub count_image: Vec<f32>,
}

/// SMAPE = mean over the masked pixels of 2|a − b| / (|a| + |b| + ε) on luminance.
pub fn smape_luminance(a: &[f32], b: &[f32], mask: &[bool]) -> f64 {
    let (mut s, mut n) = (0.0f64, 0usize);
    for ((x, y), _) in a.iter().zip(b).zip(mask).filter(|(_, m)| **m) {
        let (x, y) = (*x as f64, *y as f64);
        s += 2.0 * (x - y).abs() / (x.abs() + y.abs() + 1e-4);
        n += 1;
    }
    s / n.max(1) as f64
}

fn lum(result: &[PixelResult]) -> Vec<f32> {
    result.iter().map(|r| luminance(r.rgb)).collect()
}

fn mask(frame: &SssFrame) -> Vec<bool> {
    frame.irradiance.iter().map(|t| t[3] > 0.0).collect()
}

/// PSNR of the luminance over SSS pixels, peak `peak`.
pub fn psnr(result: &[PixelResult], reference: &[[f32; 3]], frame: &SssFrame, peak: f64) -> f64 {
    let reference: Vec<f32> = reference.iter().map(|c| luminance(*c)).collect();
    psnr_luminance(&lum(result), &reference, &mask(frame), peak)
}

/// SMAPE between two frames' results over SSS pixels.
pub fn smape(a: &[PixelResult], b: &[PixelResult], frame: &SssFrame) -> f64 {
    smape_luminance(&lum(a), &lum(b), &mask(frame))
}

/// Accumulates a run frame by frame.
#[derive(Default)]
pub struct Accumulator {
    spp_sum: f64,
    spp_n: usize,
    psnr: Vec<f64>,
    smape: Vec<f64>,
    counts: Vec<f64>,
    frames: usize,
    previous: Option<Vec<PixelResult>>,
}

impl Accumulator {
    /// Adds a frame; `reference` where this frame is measured against one.
    pub fn add(
        &mut self,
        frame: &SssFrame,
        result: Vec<PixelResult>,
        reference: Option<(&[[f32; 3]], f64)>,
    ) {
        if self.counts.is_empty() {
            self.counts = vec![0.0; result.len()];
        }
        for ((r, t), c) in result.iter().zip(&frame.irradiance).zip(&mut self.counts) {
            *c += r.count as f64;
            if t[3] > 0.0 {
                self.spp_sum += r.count as f64;
                self.spp_n += 1;
            }
        }
        if let Some((reference, peak)) = reference {
            self.psnr.push(psnr(&result, reference, frame, peak));
        }
        if let Some(p) = &self.previous {
            self.smape.push(smape(&result, p, frame));
        }
        self.previous = Some(result);
        self.frames += 1;
    }

    pub fn finish(self) -> RunMeasures {
        let mean = |v: &[f64]| {
            if v.is_empty() { f64::NAN } else { v.iter().sum::<f64>() / v.len() as f64 }
        };
        RunMeasures {
            mean_spp: self.spp_sum / self.spp_n.max(1) as f64,
            psnr_db: mean(&self.psnr),
            smape: mean(&self.smape),
            count_image: self
                .counts
                .iter()
                .map(|c| (c / self.frames.max(1) as f64) as f32)
                .collect(),
        }
    }
}
