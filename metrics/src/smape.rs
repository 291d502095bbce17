//! Frame-to-frame flicker: SMAPE between consecutive frames (reliability-weighted-nirc.txt §4.2),
//!   SMAPE(t, t-1) = 1/|Ω| Σ_p 2|I_t(p) - I_{t-1}(p)| / (|I_t(p)| + |I_{t-1}(p)| + ε),
//! evaluated per colour channel and averaged over the three channels.

use rayon::prelude::*;

use crate::image::Image;

/// Default ε of the SMAPE denominator (scenarios may override it).
pub const DEFAULT_EPS: f32 = 0.01;

#[derive(Clone, Debug)]
pub struct SmapeResult {
    /// Mean over the measured pixels.
    pub mean: f64,
    /// Per-pixel SMAPE (channel average), row-major; 0 where a pixel was not measured.
    pub map: Vec<f32>,
    /// Pixels excluded because they have no valid history (always 0 for plain [`smape`]).
    pub disoccluded_count: u64,
    /// Per-pixel exclusion mask of [`smape_reprojected`] (empty for plain [`smape`]); use it with
    /// [`crate::Region::mean_of_valid`] for region means.
    pub disoccluded: Vec<bool>,
}

#[inline]
fn smape_pixel(a: [f32; 3], b: [f32; 3], eps: f32) -> f32 {
    let mut s = 0.0;
    for c in 0..3 {
        s += 2.0 * (a[c] - b[c]).abs() / (a[c].abs() + b[c].abs() + eps);
    }
    s * (1.0 / 3.0)
}

/// Rows per parallel task: large enough that task overhead stays small.
const ROWS_PER_TASK: usize = 16;

/// SMAPE between the current and the previous frame, with its per-pixel map.
pub fn smape(cur: &Image, prev: &Image, eps: f32) -> SmapeResult {
    cur.assert_same_size(prev, "smape");
    let w = cur.width as usize;
    let (cur_flat, prev_flat) = (cur.rgb.as_flattened(), prev.rgb.as_flattened());
    let mut map = vec![0.0f32; cur.len()];
    let sum: f64 = map
        .par_chunks_mut(w * ROWS_PER_TASK)
        .enumerate()
        .map(|(chunk, out)| {
            let start = 3 * chunk * w * ROWS_PER_TASK;
            let (a, b) =
                (&cur_flat[start..start + 3 * out.len()], &prev_flat[start..start + 3 * out.len()]);
            // Per channel over a flat slice first (vectorises), then the channel average.
            let terms: Vec<f32> = a
                .iter()
                .zip(b)
                .map(|(&a, &b)| 2.0 * (a - b).abs() / (a.abs() + b.abs() + eps))
                .collect();
            let mut acc = 0.0f64;
            for (o, t) in out.iter_mut().zip(terms.chunks_exact(3)) {
                *o = (t[0] + t[1] + t[2]) * (1.0 / 3.0);
                acc += *o as f64;
            }
            acc
        })
        // Partials collected in row order and added sequentially: the same bits on any thread count.
        .collect::<Vec<f64>>()
        .iter()
        .sum();
    let n = cur.len().max(1) as f64;
    SmapeResult { mean: sum / n, map, disoccluded_count: 0, disoccluded: Vec::new() }
}

/// SMAPE between the current frame and the previous frame reprojected by motion vectors.
///
/// `motion[p]` is, for the pixel centre p of the current frame, the offset in pixels to where the
/// same surface point was in the previous frame (x right, y down): the history is read at
/// `p + motion[p]` with bilinear filtering. A pixel counts as disoccluded, and is excluded from
/// the mean (its map value is 0), when that position falls outside the previous frame or when the
/// renderer marked it by a non-finite motion vector (e.g. NaN for a surface hidden last frame).
pub fn smape_reprojected(cur: &Image, prev: &Image, motion: &[[f32; 2]], eps: f32) -> SmapeResult {
    cur.assert_same_size(prev, "smape_reprojected");
    assert_eq!(motion.len(), cur.len(), "smape_reprojected: one motion vector per pixel expected");
    let (w, h) = (cur.width as usize, cur.height as usize);
    let mut map = vec![0.0f32; cur.len()];
    let mut disoccluded = vec![true; cur.len()];
    let (sum, valid): (f64, u64) = map
        .par_chunks_mut(w)
        .zip(disoccluded.par_chunks_mut(w))
        .enumerate()
        .map(|(y, (out, mask))| {
            let mut acc = (0.0f64, 0u64);
            for (x, (o, m)) in out.iter_mut().zip(mask.iter_mut()).enumerate() {
                let i = y * w + x;
                let [mx, my] = motion[i];
                if let Some(hist) = sample_bilinear(prev, w, h, x as f32 + mx, y as f32 + my) {
                    *o = smape_pixel(cur.rgb[i], hist, eps);
                    *m = false;
                    acc.0 += *o as f64;
                    acc.1 += 1;
                }
            }
            acc
        })
        .collect::<Vec<(f64, u64)>>()
        .iter()
        .fold((0.0, 0), |a, b| (a.0 + b.0, a.1 + b.1));
    let mean = if valid > 0 { sum / valid as f64 } else { 0.0 };
    SmapeResult { mean, map, disoccluded_count: cur.len() as u64 - valid, disoccluded }
}

/// Bilinear sample at pixel coordinates (pixel centres at integers); `None` outside the image.
fn sample_bilinear(img: &Image, w: usize, h: usize, x: f32, y: f32) -> Option<[f32; 3]> {
    if !x.is_finite()
        || !y.is_finite()
        || x < -0.5
        || y < -0.5
        || x > w as f32 - 0.5
        || y > h as f32 - 0.5
    {
        return None;
    }
    let (x, y) = (x.clamp(0.0, (w - 1) as f32), y.clamp(0.0, (h - 1) as f32));
    let (x0, y0) = (x.floor() as usize, y.floor() as usize);
    let (x1, y1) = ((x0 + 1).min(w - 1), (y0 + 1).min(h - 1));
    let (fx, fy) = (x - x0 as f32, y - y0 as f32);
    let p = |xx: usize, yy: usize| img.rgb[yy * w + xx];
    Some(std::array::from_fn(|c| {
        let top = p(x0, y0)[c] * (1.0 - fx) + p(x1, y0)[c] * fx;
        let bottom = p(x0, y1)[c] * (1.0 - fx) + p(x1, y1)[c] * fx;
        top * (1.0 - fy) + bottom * fy
    }))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn identical_frames_have_zero_smape() {
        let a = Image::from_fn(40, 20, |x, y| [x as f32, y as f32, 0.5]);
        let r = smape(&a, &a, DEFAULT_EPS);
        assert_eq!(r.mean, 0.0);
        assert!(r.map.iter().all(|&v| v == 0.0));
    }

    #[test]
    fn analytic_value_per_channel_then_averaged() {
        // Channel r: 2|2-1|/(3+ε); g: 0; b: 2|0-1|/(1+ε).
        let eps = 0.01;
        let cur = Image::filled(33, 17, [2.0, 0.5, 0.0]);
        let prev = Image::filled(33, 17, [1.0, 0.5, -1.0]);
        let expected = (2.0 / (3.0 + eps) + 0.0 + 2.0 / (1.0 + eps)) / 3.0;
        let r = smape(&cur, &prev, eps);
        assert!((r.mean - expected as f64).abs() < 1e-6, "{} vs {expected}", r.mean);
        assert!(r.map.iter().all(|&v| (v - expected).abs() < 1e-6));
        // A black pixel against black is 0 thanks to ε, a black against a bright one is ~2.
        let black = Image::filled(2, 1, [0.0; 3]);
        let bright = Image::filled(2, 1, [1000.0; 3]);
        assert!((smape(&bright, &black, eps).mean - 2.0).abs() < 1e-4);
    }

    #[test]
    fn mean_is_mean_of_map() {
        let cur = Image::from_fn(50, 31, |x, y| {
            [((x * 7 + y) % 5) as f32, (x % 3) as f32, 0.1 * y as f32]
        });
        let prev = Image::from_fn(50, 31, |x, y| [((x + y * 3) % 4) as f32, (y % 2) as f32, 0.2]);
        let r = smape(&cur, &prev, 0.01);
        let m: f64 = r.map.iter().map(|&v| v as f64).sum::<f64>() / r.map.len() as f64;
        assert!((r.mean - m).abs() < 1e-9);
        assert!(r.mean > 0.1);
    }

    #[test]
    fn reprojection_undoes_a_camera_pan_and_counts_disocclusions() {
        // The scene moves 3 pixels to the right: the current pixel x saw what was at x - 3.
        let pattern =
            |x: i32, y: i32| [((x * 13 + y * 7) % 11) as f32 + 0.5, (x % 4) as f32, (y % 3) as f32];
        let prev = Image::from_fn(24, 10, |x, y| pattern(x as i32, y as i32));
        let cur = Image::from_fn(24, 10, |x, y| pattern(x as i32 - 3, y as i32));
        let motion = vec![[-3.0, 0.0]; cur.len()];
        let plain = smape(&cur, &prev, 0.01);
        assert!(plain.mean > 0.3, "the pan must flicker without reprojection");
        let rep = smape_reprojected(&cur, &prev, &motion, 0.01);
        // Columns 0..3 read outside the previous frame.
        assert_eq!(rep.disoccluded_count, 3 * 10);
        assert_eq!(rep.disoccluded.iter().filter(|&&d| d).count(), 30);
        assert!(rep.disoccluded[0] && rep.disoccluded[2] && !rep.disoccluded[3]);
        assert!(rep.mean < 1e-6, "reprojected SMAPE {}", rep.mean);
        // A renderer-flagged pixel is excluded too.
        let mut flagged = motion.clone();
        flagged[5 * 24 + 10] = [f32::NAN, f32::NAN];
        assert_eq!(smape_reprojected(&cur, &prev, &flagged, 0.01).disoccluded_count, 31);
    }

    #[test]
    fn half_pixel_motion_is_interpolated() {
        let prev = Image::from_fn(4, 1, |x, _| [x as f32, 0.0, 0.0]);
        let cur = Image::filled(4, 1, [1.5, 0.0, 0.0]);
        let motion = vec![[0.5, 0.0], [0.5, 0.0], [0.5, 0.0], [0.5, 0.0]];
        let r = smape_reprojected(&cur, &prev, &motion, 0.01);
        // Pixel 1 samples between 1 and 2 -> 1.5 exactly.
        assert_eq!(r.map[1], 0.0);
        assert_eq!(r.disoccluded_count, 0, "x = 3.5 is the right edge of the last pixel");
    }
}
