//! Reprojection of SPVG's history H and the control variates' J (Sec. 4.4.2 and P4 of Sec.
//! 5.3.2: "reprojection is performed with velocity texture"): pixel x reads the previous frame's
//! histories at x + motion, point-sampled (the thesis's C_s of eq. 4.11 is a point sampling
//! operator), the convention of the TAA resolve (methods/taa: pos = x + ½ + motion, texel
//! floor(pos), motion = previous minus current position in pixels). C_s = 0 (the reset of eqs.
//! 4.11-4.12) off screen, where the previous frame had no SSS history there, or where the depth
//! stored with that history disagrees with this pixel's by more than the TAA's tolerance.

use super::pixel::PixelHistory;

/// The previous frame's texel that pixel (x, y) came from; None off screen.
pub fn reprojected_texel(
    x: u32,
    y: u32,
    motion: [f32; 2],
    width: u32,
    height: u32,
) -> Option<usize> {
    let (px, py) = (x as f32 + 0.5 + motion[0], y as f32 + 0.5 + motion[1]);
    if !(px >= 0.0 && py >= 0.0 && px < width as f32 && py < height as f32) {
        return None;
    }
    Some(py as usize * width as usize + px as usize)
}

/// C_s ≠ 0: the reprojected history is this surface's. `w` is this pixel's pixels per scene unit
/// (depth = focal/w); the history's `w` is the one it was written with (0: unknown, no depth
/// test). |depth − depth_prev| ≤ tol·depth ⇔ |w_prev − w| ≤ tol·w_prev.
pub fn history_matches(prev: &PixelHistory, w: f32, depth_tolerance: f32) -> bool {
    prev.spvg.valid && (prev.w <= 0.0 || (prev.w - w).abs() <= depth_tolerance * prev.w)
}

/// The history pixel (x, y) reads: the reprojected one where it matches, else a reset.
pub fn reproject(
    history: &[PixelHistory],
    motion: Option<[f32; 2]>,
    (x, y): (u32, u32),
    (width, height): (u32, u32),
    w: f32,
    depth_tolerance: f32,
) -> PixelHistory {
    let texel = reprojected_texel(x, y, motion.unwrap_or([0.0; 2]), width, height);
    match texel.and_then(|i| history.get(i)) {
        Some(prev) if history_matches(prev, w, depth_tolerance) => *prev,
        _ => PixelHistory::default(),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn zero_motion_reads_the_same_pixel_and_off_screen_reads_nothing() {
        assert_eq!(reprojected_texel(3, 2, [0.0, 0.0], 8, 4), Some(2 * 8 + 3));
        assert_eq!(reprojected_texel(3, 2, [-1.4, 1.2], 8, 4), Some(3 * 8 + 2));
        assert_eq!(reprojected_texel(0, 0, [-0.6, 0.0], 8, 4), None);
        assert_eq!(reprojected_texel(7, 3, [0.0, 0.5], 8, 4), None);
    }
}
