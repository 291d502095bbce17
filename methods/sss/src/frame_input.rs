//! The SSS pass's input for one frame: the demodulated diffuse irradiance and the profile's
//! scale per pixel, the motion its histories are reprojected by.

/// One frame's input, row-major: per pixel the demodulated diffuse irradiance (rgb) and w, the
/// pixels per unit of d at that pixel (0: not an SSS pixel; 1 when d is given in pixels); the
/// profile's d per channel (in pixels where w = 1); the focal length in pixels.
#[derive(Clone, Debug)]
pub struct SssFrame {
    pub width: u32,
    pub height: u32,
    pub irradiance: Vec<[f32; 4]>,
    pub d_px: [f32; 3],
    /// Pixels per scene unit at unit depth (depth = focal_px / w): eq. 7.1's depth difference;
    /// 0 where depth is unknown (no depth term).
    pub focal_px: f32,
    /// Per pixel, where it was in the previous frame minus where it is (pixels, x right, y
    /// down; the G-buffer's motion): the histories are read there. Empty: a still view.
    pub motion: Vec<[f32; 2]>,
}

impl SssFrame {
    /// The channel that radii are sampled for: the widest profile.
    pub fn d_sample(&self) -> f32 {
        self.d_px[0].max(self.d_px[1]).max(self.d_px[2])
    }
}
