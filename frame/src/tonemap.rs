//! Display transform for the PNG previews: exposure, ACES filmic curve (Narkowicz 2015 fit),
//! sRGB encoding. EXR files keep the linear radiance; only previews pass through here.

pub fn aces_narkowicz(x: f32) -> f32 {
    let (a, b, c, d, e) = (2.51, 0.03, 2.43, 0.59, 0.14);
    ((x * (a * x + b)) / (x * (c * x + d) + e)).clamp(0.0, 1.0)
}

pub fn linear_to_srgb(x: f32) -> f32 {
    if x <= 0.003_130_8 { 12.92 * x } else { 1.055 * x.powf(1.0 / 2.4) - 0.055 }
}

/// RGB8 bytes of linear RGBA radiance. NaN/Inf show as magenta so they cannot hide.
pub fn to_srgb8(rgba: &[[f32; 4]], exposure: f32) -> Vec<u8> {
    let mut out = Vec::with_capacity(rgba.len() * 3);
    for p in rgba {
        if !(p[0].is_finite() && p[1].is_finite() && p[2].is_finite()) {
            out.extend_from_slice(&[255, 0, 255]);
            continue;
        }
        for c in &p[..3] {
            let v = linear_to_srgb(aces_narkowicz(c.max(0.0) * exposure));
            out.push((v * 255.0 + 0.5) as u8);
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn curve_is_monotone_and_bounded() {
        let mut last = -1.0;
        for i in 0..1000 {
            let v = aces_narkowicz(i as f32 * 0.05);
            assert!(v >= last && (0.0..=1.0).contains(&v));
            last = v;
        }
        assert_eq!(to_srgb8(&[[0.0, 0.0, 0.0, 1.0]], 1.0), vec![0, 0, 0]);
        assert_eq!(to_srgb8(&[[f32::NAN, 0.0, 0.0, 1.0]], 1.0), vec![255, 0, 255]);
        assert!((linear_to_srgb(1.0) - 1.0).abs() < 1e-6);
    }
}
