//! The hybrid pass of the thesis's Sec. 5.3.2 ("importance-guided acceleration"): AFIS and the
//! separable approximation in one frame, chosen per thread group (8x8 tile), in the thesis's
//! pass order: a setup pass registers each tile's technique; P1 runs AFIS (Algorithm 2 with SPVG
//! counts) on the AFIS tiles into buffer one; P2, the horizontal separable pass, writes buffer one
//! on the separable tiles (the AFIS tiles keep their AFIS result there: "we use the AFIS result
//! as an approximation for the first pass in the Separable filter", so the vertical pass reads no
//! hole at a border); P3, the vertical pass, writes buffer two on the separable tiles; P4 copies
//! the AFIS tiles' result from buffer one into buffer two. CPU twin of shaders/hybrid.wgsl.
//!
//! The decision rule. The thesis leaves the technique to the user ("the type can be
//! pre-determined or by custom process on the fly") and motivates the choice by the separable
//! approximation's banding in close views. The rule here makes that reason explicit: the
//! separable kernel's taps sit at Jimenez's quadratic offsets, widest apart at the ends; where a
//! tile's largest profile d (in pixels) spreads the outermost gap over more than `max_gap_px`
//! pixels, the 1-D passes skip texels and band, and the tile takes AFIS; elsewhere separable.

use super::frame_input::SssFrame;
use super::pixel::{PixelHistory, PixelResult};
use super::separable;
use serde::{Deserialize, Serialize};

/// The thread group edge (the passes' 8x8 workgroups): the unit the technique is chosen for.
pub const TILE: u32 = 8;

/// The hybrid's settings: the separable passes' taps and the rule's largest tap gap in pixels.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct Hybrid {
    /// Taps per 1-D pass on the separable tiles (odd, 3 to `separable::MAX_TAPS`).
    pub taps: u32,
    /// A tile takes AFIS where the separable kernel's outermost taps would lie more than this
    /// many pixels apart at one of its SSS pixels (1: every texel under the kernel is read).
    pub max_gap_px: f32,
}

impl Default for Hybrid {
    fn default() -> Self {
        Self { taps: 25, max_gap_px: 1.0 }
    }
}

/// A tile's technique (the GPU's tile buffer holds these codes).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Technique {
    Separable = 0,
    Afis = 1,
}

impl Hybrid {
    pub fn validate(&self) -> Result<(), String> {
        if self.taps < 3 || self.taps.is_multiple_of(2) || self.taps > separable::MAX_TAPS {
            return Err(format!(
                "hybrid taps {}; expected an odd count in [3, {}]",
                self.taps,
                separable::MAX_TAPS
            ));
        }
        if !(self.max_gap_px > 0.0) {
            return Err(format!(
                "hybrid max_gap_px {}; expected a positive number of pixels (or infinity: separable everywhere)",
                self.max_gap_px
            ));
        }
        Ok(())
    }

    /// The sampled d (pixels) from which a pixel asks for AFIS: the outermost gap of the tap
    /// offsets, in units of d, stretched to `max_gap_px`.
    pub fn min_d_px(&self) -> f32 {
        let o = separable::tap_offsets(self.taps);
        let gap = o[o.len() - 1] - o[o.len() - 2];
        (self.max_gap_px as f64 / gap) as f32
    }
}

/// The setup pass: per tile (row-major, ⌈w/8⌉ x ⌈h/8⌉), AFIS where some SSS pixel's sampled d
/// (d_sample · w, the same f32 product as the GPU's) reaches `min_d_px`; separable elsewhere
/// (tiles without SSS pixels too: they pass through either way).
pub fn tile_techniques(frame: &SssFrame, hybrid: &Hybrid) -> Vec<Technique> {
    let (tx, ty) = (frame.width.div_ceil(TILE), frame.height.div_ceil(TILE));
    let (ds, min_d) = (frame.d_sample(), hybrid.min_d_px());
    let mut out = vec![Technique::Separable; (tx * ty) as usize];
    for y in 0..frame.height {
        for x in 0..frame.width {
            let w = frame.irradiance[(y * frame.width + x) as usize][3];
            if w > 0.0 && ds * w >= min_d {
                out[((y / TILE) * tx + x / TILE) as usize] = Technique::Afis;
            }
        }
    }
    out
}

/// Pixel i's tile's technique.
pub fn technique_at(frame: &SssFrame, tiles: &[Technique], i: usize) -> Technique {
    let (x, y) = (i as u32 % frame.width, i as u32 / frame.width);
    tiles[((y / TILE) * frame.width.div_ceil(TILE) + x / TILE) as usize]
}

/// P2-P4 on the CPU after P1, `p1` (the settings' Monte Carlo variant on the prefiltered chain
/// over the whole image, with its histories; each pixel reads only the irradiance, the chain and
/// its own history, so the others' results do not change it): P1's result and histories on the
/// AFIS tiles, the two separable passes elsewhere; separable pixels keep no history (an AFIS tile
/// that was separable last frame cold-starts, eqs. 4.11-4.12).
pub fn step(
    frame: &SssFrame,
    hybrid: &Hybrid,
    p1: (Vec<PixelResult>, Vec<PixelHistory>),
) -> (Vec<PixelResult>, Vec<PixelHistory>) {
    let tiles = tile_techniques(frame, hybrid);
    let afis = |i: usize| technique_at(frame, &tiles, i) == Technique::Afis;
    let (p1, mut next) = p1;
    let kernel = separable::kernel(hybrid.taps, frame.d_px).unwrap_or_else(|e| panic!("{e}"));
    // P2: buffer one, horizontal on the separable tiles, the AFIS result on the AFIS tiles.
    let mut one = separable::pass(frame, &frame.irradiance, &kernel, true);
    for (i, v) in one.iter_mut().enumerate() {
        if afis(i) {
            let r = p1[i];
            *v = [r.rgb[0], r.rgb[1], r.rgb[2], frame.irradiance[i][3]];
        }
    }
    // P3 on the separable tiles, P4 (the copy) on the AFIS tiles.
    let two = separable::pass(frame, &one, &kernel, false);
    let results = (0..two.len())
        .map(|i| {
            if afis(i) {
                return p1[i];
            }
            next[i] = PixelHistory::default();
            let sss = frame.irradiance[i][3] > 0.0;
            PixelResult {
                rgb: [two[i][0], two[i][1], two[i][2]],
                count: if sss { 2 * hybrid.taps } else { 0 },
            }
        })
        .collect();
    (results, next)
}
