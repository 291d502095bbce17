//! Primary-ray transmittance images on the CPU (paper Figs. 8 and 10): per pixel, `spp`
//! estimates along the camera ray through the pixel centre, each with its own stream
//! (`rng::image_seed`), reduced to the mean, the per-pixel standard deviation of one estimate
//! and the density lookups; and the exact image by regular tracking (the bias maps' reference:
//! exact for nearest-neighbour voxels, where the paper uses 2^18 spp).

use glam::{Vec2, Vec3};
use render::frame::CameraBasis;

use crate::medium::{Estimate, Medium};
use crate::regular_tracking::optical_depth;
use crate::rng::{Pcg, image_seed};
use crate::transmittance::Estimator;

/// Rays end here (primary rays meet no surfaces in these images).
pub const T_MAX: f32 = 1.0e4;

/// Unit ray directions through the pixel centres, row-major.
pub fn directions(camera: &CameraBasis, width: u32, height: u32) -> Vec<Vec3> {
    (0..height)
        .flat_map(|y| {
            (0..width).map(move |x| {
                camera.ray_direction(Vec2::new(x as f32 + 0.5, y as f32 + 0.5), width, height)
            })
        })
        .collect()
}

/// Which image of a run: its seed and frame.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct ImageKey {
    pub seed: u32,
    pub frame: u32,
    pub spp: u32,
}

/// All estimates, pixel-major (`spp` per pixel), as the GPU pass writes them.
pub fn estimates(
    medium: &Medium,
    origin: Vec3,
    dirs: &[Vec3],
    estimator: Estimator,
    key: ImageKey,
) -> Vec<Estimate> {
    let mut out = Vec::with_capacity(dirs.len() * key.spp as usize);
    for (pixel, &d) in dirs.iter().enumerate() {
        for sample in 0..key.spp {
            let mut rng = Pcg::new(image_seed(key.seed, key.frame, pixel as u32, sample));
            out.push(match medium.segment(origin, d, T_MAX) {
                Some(seg) => estimator.estimate(medium, &seg, &mut rng),
                None => Estimate { value: 1.0, lookups: 0 },
            });
        }
    }
    out
}

/// Per pixel: the mean, the standard deviation of one estimate (n − 1) and the mean lookups.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct PixelStats {
    pub mean: Vec<f32>,
    pub std: Vec<f32>,
    pub lookups: Vec<f32>,
}

pub fn reduce(estimates: &[Estimate], spp: u32) -> PixelStats {
    let mut s = PixelStats::default();
    for px in estimates.chunks(spp as usize) {
        let n = px.len() as f64;
        let mean = px.iter().map(|e| f64::from(e.value)).sum::<f64>() / n;
        let var = px.iter().map(|e| (f64::from(e.value) - mean).powi(2)).sum::<f64>()
            / (n - 1.0).max(1.0);
        s.mean.push(mean as f32);
        s.std.push(var.sqrt() as f32);
        s.lookups.push((px.iter().map(|e| f64::from(e.lookups)).sum::<f64>() / n) as f32);
    }
    s
}

/// RMS over pixels of the noise-corrected bias: per pixel (mean − T)² − s²/spp is an unbiased
/// estimate of the squared bias, so the figure does not drown in the noise of the mean as mean
/// |mean − T| does at a few dozen estimates per pixel (the paper reads bias from 2^18 spp).
pub fn rms_bias(stats: &PixelStats, exact: &[f32], spp: u32) -> f64 {
    let b2: f64 = stats
        .mean
        .iter()
        .zip(&stats.std)
        .zip(exact)
        .map(|((m, s), t)| f64::from(m - t).powi(2) - f64::from(*s).powi(2) / f64::from(spp))
        .sum::<f64>()
        / exact.len() as f64;
    b2.max(0.0).sqrt()
}

/// exp(−τ) per pixel by regular tracking.
pub fn exact(medium: &Medium, origin: Vec3, dirs: &[Vec3]) -> Vec<f32> {
    dirs.iter()
        .map(|&d| {
            medium
                .segment(origin, d, T_MAX)
                .map_or(1.0, |seg| (-optical_depth(medium, &seg)).exp() as f32)
        })
        .collect()
}
