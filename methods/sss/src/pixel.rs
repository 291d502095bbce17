//! What the SSS pass keeps and gives per pixel: its histories (SPVG's and the control variates')
//! and its result.

use super::control_variates::EmCovariance;
use super::spvg::SpvgHistory;

/// A pixel's histories: SPVG's H and the control variates' J, and the w (pixels per scene
/// unit, depth = focal/w) they were written at, for the reprojection's depth test (0: unknown).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct PixelHistory {
    pub spvg: SpvgHistory,
    pub cv: EmCovariance,
    pub w: f32,
}

/// A pixel's result: the scattered irradiance and the count it took.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct PixelResult {
    pub rgb: [f32; 3],
    pub count: u32,
}
