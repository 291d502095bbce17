//! LDR-FLIP (Andersson et al. 2020): per-pixel perceived difference between two linear-RGB
//! images in [0, 1] seen at `ppd` pixels per degree.
//!
//!   colour pipeline:  RGB -> YCxCz -> CSF filtering -> RGB (clamped) -> CIELAB -> Hunt -> HyAB,
//!                     ΔE_c = HyAB^q_c, redistributed to [0, 1] so that p_c·c_max maps to p_t;
//!   feature pipeline: edges and points of the normalised achromatic channel,
//!                     ΔE_f = (max(|Δedge|, |Δpoint|) / √2)^q_f;
//!   FLIP = ΔE_c^(1 - ΔE_f).
//! Borders are handled by clamping coordinates to the image (edge pixels repeat).

use rayon::prelude::*;

use super::color::{ColorSpace, hunt, hyab};
use super::csf::SpatialFilters;
use super::features::FeatureFilters;

/// Exponent compressing colour differences.
pub const QC: f32 = 0.7;
/// Fraction of c_max below which errors are mapped to [0, p_t].
pub const PC: f32 = 0.4;
/// Share of the error range given to differences below p_c·c_max.
pub const PT: f32 = 0.95;
/// Exponent of the feature difference.
pub const QF: f32 = 0.5;

/// Sums `taps[k] * value(clamped index)` over the window centred on `i`.
#[inline]
fn clamped(i: usize, k: usize, radius: usize, len: usize) -> usize {
    (i + k).saturating_sub(radius).min(len - 1)
}

/// Computes the LDR-FLIP map of `test` against `reference`, both linear RGB clamped to [0, 1].
pub fn ldr_flip_map(
    reference: &[[f32; 3]],
    test: &[[f32; 3]],
    width: usize,
    height: usize,
    ppd: f32,
) -> Vec<f32> {
    assert_eq!(reference.len(), width * height);
    assert_eq!(test.len(), width * height);
    let cs = ColorSpace::default();
    let to_ycxcz = |img: &[[f32; 3]]| -> Vec<[f32; 3]> {
        img.par_iter().map(|p| cs.linear_rgb_to_ycxcz(p.map(|c| c.clamp(0.0, 1.0)))).collect()
    };
    let r = to_ycxcz(reference);
    let t = to_ycxcz(test);
    let color = color_difference(&cs, &r, &t, width, height, ppd);
    feature_difference_and_combine(&r, &t, color, width, height, ppd)
}

/// CSF-filtered HyAB colour difference, redistributed to [0, 1].
fn color_difference(
    cs: &ColorSpace,
    r: &[[f32; 3]],
    t: &[[f32; 3]],
    w: usize,
    h: usize,
    ppd: f32,
) -> Vec<f32> {
    let f = SpatialFilters::new(ppd);
    let n = f.y.len();
    // Horizontal pass: per pixel (Y, Cx, Cz·cz1, Cz·cz2) for reference and test.
    let mut horizontal = vec![[[0.0f32; 4]; 2]; w * h];
    horizontal.par_chunks_mut(w).enumerate().for_each(|(y, row)| {
        let base = y * w;
        for (x, out) in row.iter_mut().enumerate() {
            let mut acc = [[0.0f32; 4]; 2];
            for k in 0..n {
                let xx = clamped(x, k, f.radius, w);
                for (img, a) in [r, t].iter().zip(acc.iter_mut()) {
                    let p = img[base + xx];
                    a[0] += f.y[k] * p[0];
                    a[1] += f.cx[k] * p[1];
                    a[2] += f.cz1[k] * p[2];
                    a[3] += f.cz2[k] * p[2];
                }
            }
            *out = acc;
        }
    });
    let cmax = cs.max_color_distance(QC);
    let pccmax = PC * cmax;
    let mut out = vec![0.0f32; w * h];
    out.par_chunks_mut(w).enumerate().for_each(|(y, row)| {
        for (x, o) in row.iter_mut().enumerate() {
            let mut acc = [[0.0f32; 4]; 2];
            for k in 0..n {
                let yy = clamped(y, k, f.radius, h);
                let hp = &horizontal[yy * w + x];
                for (src, a) in hp.iter().zip(acc.iter_mut()) {
                    a[0] += f.y[k] * src[0];
                    a[1] += f.cx[k] * src[1];
                    a[2] += f.cz1[k] * src[2];
                    a[3] += f.cz2[k] * src[3];
                }
            }
            // Filtered colours may leave the gamut: clamp in linear RGB, then go to Hunt-adjusted CIELAB.
            let perceptual = |a: [f32; 4]| {
                let rgb = cs
                    .xyz_to_linear_rgb(cs.ycxcz_to_xyz([a[0], a[1], a[2] + a[3]]))
                    .map(|c| c.clamp(0.0, 1.0));
                hunt(cs.xyz_to_lab(cs.linear_rgb_to_xyz(rgb)))
            };
            let de = hyab(perceptual(acc[0]), perceptual(acc[1])).powf(QC);
            *o = if de < pccmax {
                de * (PT / pccmax)
            } else {
                PT + ((de - pccmax) / (cmax - pccmax)) * (1.0 - PT)
            };
        }
    });
    out
}

/// Edge/point feature difference, combined with the colour difference into the FLIP value.
fn feature_difference_and_combine(
    r: &[[f32; 3]],
    t: &[[f32; 3]],
    color: Vec<f32>,
    w: usize,
    h: usize,
    ppd: f32,
) -> Vec<f32> {
    let f = FeatureFilters::new(ppd);
    let n = f.g.len();
    // Achromatic channel normalised to [0, 1].
    let gray = |p: [f32; 3]| p[0] * (1.0 / 116.0) + 16.0 / 116.0;
    // Horizontal pass: (dG/dx, d²G/dx², G) along x, for reference and test.
    let mut horizontal = vec![[[0.0f32; 3]; 2]; w * h];
    horizontal.par_chunks_mut(w).enumerate().for_each(|(y, row)| {
        let base = y * w;
        for (x, out) in row.iter_mut().enumerate() {
            let mut acc = [[0.0f32; 3]; 2];
            for k in 0..n {
                let xx = clamped(x, k, f.radius, w);
                for (img, a) in [r, t].iter().zip(acc.iter_mut()) {
                    let v = gray(img[base + xx]);
                    a[0] += f.dg[k] * v;
                    a[1] += f.ddg[k] * v;
                    a[2] += f.g[k] * v;
                }
            }
            *out = acc;
        }
    });
    let mut out = color;
    out.par_chunks_mut(w).enumerate().for_each(|(y, row)| {
        for (x, o) in row.iter_mut().enumerate() {
            // Per image: [dx, ddx, dy, ddy].
            let mut acc = [[0.0f32; 4]; 2];
            for k in 0..n {
                let yy = clamped(y, k, f.radius, h);
                for (src, a) in horizontal[yy * w + x].iter().zip(acc.iter_mut()) {
                    a[0] += f.g[k] * src[0];
                    a[1] += f.g[k] * src[1];
                    a[2] += f.dg[k] * src[2];
                    a[3] += f.ddg[k] * src[2];
                }
            }
            let edge = |a: &[f32; 4]| (a[0] * a[0] + a[2] * a[2]).sqrt();
            let point = |a: &[f32; 4]| (a[1] * a[1] + a[3] * a[3]).sqrt();
            let d_edge = (edge(&acc[0]) - edge(&acc[1])).abs();
            let d_point = (point(&acc[0]) - point(&acc[1])).abs();
            let feature = (std::f32::consts::FRAC_1_SQRT_2 * d_edge.max(d_point)).powf(QF);
            *o = o.powf(1.0 - feature);
        }
    });
    out
}
