//! ColorVideoVDP (Mantiuk et al., SIGGRAPH 2024): how visible the difference between a test
//! sequence and its reference is, in JOD (10 = no visible difference, lower is worse), with
//! temporal channels that respond to flicker. Computed by the `colorvideovdp` crate, a port of
//! the authors' `cvvdp` package; `tests/cvvdp_fixtures.rs` holds it to `cvvdp`'s scores.
//!
//! Our frames are scene-referred linear RGB. What the display shows is the frame as the run's
//! PNGs show it: radiance times `exposure`, clipped to [0, 1], sRGB-encoded; the display model
//! then turns that into luminance (its peak, black level and reflected ambient light).

use anyhow::{Context, bail};
use colorvideovdp::{Color, Cvvdp, DisplayModel, Options};
use serde::{Deserialize, Serialize};

use crate::image::{Image, linear_to_srgb};

/// The display a run is judged on when the scenario names none: a 24-inch 1920x1080 SDR
/// monitor of 200 cd/m² seen from 0.6 m in an office (250 lux), the metric's own default.
pub const DEFAULT_DISPLAY: &str = "standard_fhd";

/// The most memory one prediction may take, bytes (the crate's estimate of its buffers).
pub const MEMORY_LIMIT: usize = 6 << 30;

/// How JOD sees a run: the display model and the radiance-to-display mapping.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct CvvdpSettings {
    /// A display of the metric's set (`colorvideovdp::DisplayModel::names`).
    pub display: String,
    /// Radiance 1.0 times `exposure` is the display's peak (white).
    pub exposure: f32,
    /// Whether the report computes JOD at all (it reads every recorded frame back).
    pub enabled: bool,
}

impl Default for CvvdpSettings {
    fn default() -> Self {
        Self { display: DEFAULT_DISPLAY.into(), exposure: 1.0, enabled: true }
    }
}

impl CvvdpSettings {
    /// What is wrong with these settings, if anything (an unknown display, a bad exposure).
    pub fn problem(&self) -> Option<String> {
        if DisplayModel::from_name(&self.display).is_err() {
            let names = display_names().join(", ");
            return Some(format!("unknown display '{}'; expected one of {names}", self.display));
        }
        if !(self.exposure.is_finite() && self.exposure > 0.0) {
            return Some(format!("exposure {}; expected a positive number", self.exposure));
        }
        None
    }
}

/// The metric's displays.
pub fn display_names() -> Vec<&'static str> {
    DisplayModel::names().unwrap_or_default()
}

/// The frame as the display receives it: exposure, clipping, sRGB encoding (f32, interleaved).
pub fn display_encoded(image: &Image, exposure: f32) -> Vec<f32> {
    image
        .rgb
        .iter()
        .flat_map(|p| p.map(|c| linear_to_srgb((c * exposure).clamp(0.0, 1.0))))
        .collect()
}

/// JOD of a sequence and, when asked, its distortion map per frame (`1 - JOD_pixel / 10`).
#[derive(Clone, Debug)]
pub struct JodResult {
    pub jod: f64,
    pub maps: Option<Vec<Vec<f32>>>,
}

/// ColorVideoVDP of `test` against `reference` (same length and size, at least 4x4), played at
/// `fps` on the settings' display. One frame is judged as an image.
pub fn jod(
    reference: &[Image],
    test: &[Image],
    fps: f32,
    settings: &CvvdpSettings,
    maps: bool,
) -> anyhow::Result<JodResult> {
    if let Some(p) = settings.problem() {
        bail!("cvvdp: {p}");
    }
    if reference.len() != test.len() || reference.is_empty() {
        bail!(
            "cvvdp: {} reference and {} test frames; expected the same number, at least one",
            reference.len(),
            test.len()
        );
    }
    let convert = |frames: &[Image]| -> anyhow::Result<Vec<colorvideovdp::Image>> {
        frames
            .iter()
            .map(|f| {
                colorvideovdp::Image::new(
                    f.width as usize,
                    f.height as usize,
                    3,
                    display_encoded(f, settings.exposure),
                )
                .map_err(|e| anyhow::anyhow!("cvvdp: {e}"))
            })
            .collect()
    };
    let (r, t) = (convert(reference)?, convert(test)?);
    let display = DisplayModel::from_name(&settings.display)
        .map_err(|e| anyhow::anyhow!("cvvdp: display '{}': {e}", settings.display))?;
    // The crate refuses predictions over 1 GiB by default; a run's map of every frame (4 bytes
    // a pixel a frame) passes that at 1280x720 after about 290 frames.
    let options =
        Options::default().with_distortion_map(maps).with_memory_limit_bytes(MEMORY_LIMIT);
    let metric = Cvvdp::new(display, options).map_err(|e| anyhow::anyhow!("cvvdp: {e}"))?;
    let prediction = if t.len() == 1 {
        metric.predict_image(&t[0], &r[0], Color::Srgb)
    } else {
        metric.predict_video(&t, &r, fps, Color::Srgb)
    }
    .map_err(|e| anyhow::anyhow!("cvvdp: {e}"))
    .context("ColorVideoVDP")?;
    let maps = prediction.distortion_map.map(|m| {
        let n = m.width * m.height;
        m.data.chunks(n).map(<[f32]>::to_vec).collect()
    });
    Ok(JodResult { jod: prediction.jod as f64, maps })
}

#[cfg(test)]
mod tests {
    use super::*;

    fn frame(v: f32) -> Image {
        Image::from_fn(16, 16, |x, y| [v * (1.0 + ((x + y) % 3) as f32 * 0.1); 3])
    }

    #[test]
    fn identical_sequences_score_ten_and_flicker_scores_less() {
        let s = CvvdpSettings::default();
        let reference: Vec<Image> = (0..6).map(|_| frame(0.4)).collect();
        let same = jod(&reference, &reference, 30.0, &s, false).unwrap();
        assert!((same.jod - 10.0).abs() < 1e-4, "{}", same.jod);
        let flicker: Vec<Image> =
            (0..6).map(|i| frame(if i % 2 == 0 { 0.3 } else { 0.5 })).collect();
        // The same error in every frame: a fixed pattern, no change over time.
        let pattern = Image::from_fn(16, 16, |x, y| [0.4 + 0.1 * ((x * 7 + y * 3) % 2) as f32; 3]);
        let steady: Vec<Image> = (0..6).map(|_| pattern.clone()).collect();
        let f = jod(&reference, &flicker, 30.0, &s, true).unwrap();
        let st = jod(&reference, &steady, 30.0, &s, false).unwrap();
        assert!(f.jod < st.jod && st.jod < 10.0, "flicker {} steady {}", f.jod, st.jod);
        let maps = f.maps.unwrap();
        assert_eq!((maps.len(), maps[0].len()), (6, 256));
    }

    #[test]
    fn unknown_displays_and_mismatched_sequences_are_refused() {
        let bad = CvvdpSettings { display: "crt_1985".into(), ..Default::default() };
        let msg = bad.problem().unwrap();
        assert!(msg.contains("crt_1985") && msg.contains("standard_fhd"), "{msg}");
        let err = jod(&[frame(0.1)], &[], 30.0, &CvvdpSettings::default(), false).unwrap_err();
        assert!(format!("{err:#}").contains("same number"));
    }
}
