//! Regions of interest: named rectangles (the papers' "steady" and "changing" crops). Metrics are
//! computed on the whole image and their per-pixel maps averaged over the rectangle, so filters
//! near the crop border still see the real neighbourhood.

use serde::{Deserialize, Serialize};

use crate::image::Image;

#[derive(Clone, Debug, PartialEq, Eq, Serialize, Deserialize)]
pub struct Region {
    pub name: String,
    pub x: u32,
    pub y: u32,
    pub width: u32,
    pub height: u32,
}

impl Region {
    /// The rectangle intersected with a `width` x `height` image: (x0, y0, x1, y1), exclusive ends.
    fn clip(&self, width: u32, height: u32) -> (u32, u32, u32, u32) {
        let x1 = self.x.saturating_add(self.width).min(width);
        let y1 = self.y.saturating_add(self.height).min(height);
        (self.x.min(x1), self.y.min(y1), x1, y1)
    }

    /// Mean of a per-pixel map (row-major, `width` wide) over the region; `None` if the region
    /// lies outside the image.
    pub fn mean_of(&self, map: &[f32], width: u32) -> Option<f64> {
        let height = map.len() as u32 / width.max(1);
        let (x0, y0, x1, y1) = self.clip(width, height);
        let n = (x1 - x0) as usize * (y1 - y0) as usize;
        if n == 0 {
            return None;
        }
        let mut sum = 0.0f64;
        for y in y0..y1 {
            let row = &map[(y * width) as usize..][..width as usize];
            sum += row[x0 as usize..x1 as usize].iter().map(|&v| v as f64).sum::<f64>();
        }
        Some(sum / n as f64)
    }

    /// Mean over the region of a map where some pixels were not measured (`valid[i] == false`).
    pub fn mean_of_valid(
        &self,
        map: &[f32],
        valid: impl Fn(usize) -> bool,
        width: u32,
    ) -> Option<f64> {
        let height = map.len() as u32 / width.max(1);
        let (x0, y0, x1, y1) = self.clip(width, height);
        let (mut sum, mut n) = (0.0f64, 0usize);
        for y in y0..y1 {
            for x in x0..x1 {
                let i = (y * width + x) as usize;
                if valid(i) {
                    sum += map[i] as f64;
                    n += 1;
                }
            }
        }
        (n > 0).then(|| sum / n as f64)
    }

    /// The region cut out of an image (clipped to it).
    pub fn crop(&self, image: &Image) -> Image {
        let (x0, y0, x1, y1) = self.clip(image.width, image.height);
        Image::from_fn(x1 - x0, y1 - y0, |x, y| image.get(x0 + x, y0 + y))
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::{flip_ldr, smape};

    #[test]
    fn region_means_select_their_rectangle() {
        let map: Vec<f32> = (0..6 * 4).map(|i| if i % 6 >= 3 { 1.0 } else { 0.0 }).collect();
        let left = Region { name: "steady".into(), x: 0, y: 0, width: 3, height: 4 };
        let right = Region { name: "changing".into(), x: 3, y: 1, width: 10, height: 2 };
        assert_eq!(left.mean_of(&map, 6), Some(0.0));
        assert_eq!(right.mean_of(&map, 6), Some(1.0));
        let outside = Region { name: "none".into(), x: 9, y: 0, width: 2, height: 2 };
        assert_eq!(outside.mean_of(&map, 6), None);
        assert_eq!(right.mean_of_valid(&map, |i| i != 9, 6), Some(1.0));
    }

    #[test]
    fn steady_and_changing_crops_of_real_metrics() {
        // The right half changes between frames, the left half does not.
        let prev = Image::from_fn(48, 24, |x, y| {
            [0.3 + 0.01 * (x % 5) as f32, 0.2, 0.1 + 0.01 * y as f32]
        });
        let cur =
            Image::from_fn(48, 24, |x, y| if x >= 24 { [0.9, 0.1, 0.5] } else { prev.get(x, y) });
        let steady = Region { name: "steady".into(), x: 0, y: 0, width: 12, height: 24 };
        let changing = Region { name: "changing".into(), x: 30, y: 0, width: 18, height: 24 };
        let s = smape(&cur, &prev, 0.01);
        assert_eq!(steady.mean_of(&s.map, 48), Some(0.0));
        assert!(changing.mean_of(&s.map, 48).unwrap() > 0.5);
        let f = flip_ldr(&prev, &cur, 67.0);
        assert!(steady.mean_of(&f.map, 48).unwrap() < 1e-6);
        assert!(changing.mean_of(&f.map, 48).unwrap() > 0.3);
        let crop = changing.crop(&cur);
        assert_eq!((crop.width, crop.height), (18, 24));
        assert_eq!(crop.get(0, 0), [0.9, 0.1, 0.5]);
    }
}
