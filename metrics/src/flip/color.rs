//! FLIP's colour pipeline: linear sRGB <-> CIE XYZ (D65) <-> YCxCz (the opponent space in which
//! the contrast sensitivity filters act) and CIELAB with the Hunt adjustment and the HyAB
//! distance (the space in which colour differences are measured).

/// Linear sRGB -> XYZ (D65), the exact rational form of the sRGB primaries' matrix.
const RGB_TO_XYZ: [[f64; 3]; 3] = [
    [10135552.0 / 24577794.0, 8788810.0 / 24577794.0, 4435075.0 / 24577794.0],
    [2613072.0 / 12288897.0, 8788810.0 / 12288897.0, 887015.0 / 12288897.0],
    [1425312.0 / 73733382.0, 8788810.0 / 73733382.0, 70074185.0 / 73733382.0],
];

/// Matrices and reference white in f32, derived once from [`RGB_TO_XYZ`].
#[derive(Clone, Debug)]
pub struct ColorSpace {
    rgb_to_xyz: [[f32; 3]; 3],
    xyz_to_rgb: [[f32; 3]; 3],
    /// XYZ of linear white (1, 1, 1): the D65 reference illuminant of YCxCz and CIELAB.
    white: [f32; 3],
    inv_white: [f32; 3],
}

fn mat_mul(m: &[[f32; 3]; 3], v: [f32; 3]) -> [f32; 3] {
    [
        m[0][0] * v[0] + m[0][1] * v[1] + m[0][2] * v[2],
        m[1][0] * v[0] + m[1][1] * v[1] + m[1][2] * v[2],
        m[2][0] * v[0] + m[2][1] * v[1] + m[2][2] * v[2],
    ]
}

fn invert(m: &[[f64; 3]; 3]) -> [[f64; 3]; 3] {
    let det = m[0][0] * (m[1][1] * m[2][2] - m[1][2] * m[2][1])
        - m[0][1] * (m[1][0] * m[2][2] - m[1][2] * m[2][0])
        + m[0][2] * (m[1][0] * m[2][1] - m[1][1] * m[2][0]);
    // inv[r][c] = cofactor(c, r) / det; cyclic indices give the cofactor's sign for free.
    std::array::from_fn(|r| {
        std::array::from_fn(|c| {
            let (r1, r2) = ((c + 1) % 3, (c + 2) % 3);
            let (c1, c2) = ((r + 1) % 3, (r + 2) % 3);
            (m[r1][c1] * m[r2][c2] - m[r1][c2] * m[r2][c1]) / det
        })
    })
}

impl Default for ColorSpace {
    fn default() -> Self {
        let to_f32 = |m: [[f64; 3]; 3]| m.map(|row| row.map(|v| v as f32));
        let white64: [f64; 3] = std::array::from_fn(|r| RGB_TO_XYZ[r].iter().sum());
        Self {
            rgb_to_xyz: to_f32(RGB_TO_XYZ),
            xyz_to_rgb: to_f32(invert(&RGB_TO_XYZ)),
            white: white64.map(|v| v as f32),
            inv_white: white64.map(|v| (1.0 / v) as f32),
        }
    }
}

impl ColorSpace {
    pub fn linear_rgb_to_xyz(&self, rgb: [f32; 3]) -> [f32; 3] {
        mat_mul(&self.rgb_to_xyz, rgb)
    }

    pub fn xyz_to_linear_rgb(&self, xyz: [f32; 3]) -> [f32; 3] {
        mat_mul(&self.xyz_to_rgb, xyz)
    }

    /// YCxCz: the linear analogue of CIELAB (no cube root), used for spatial filtering.
    pub fn xyz_to_ycxcz(&self, xyz: [f32; 3]) -> [f32; 3] {
        let [x, y, z] =
            [xyz[0] * self.inv_white[0], xyz[1] * self.inv_white[1], xyz[2] * self.inv_white[2]];
        [116.0 * y - 16.0, 500.0 * (x - y), 200.0 * (y - z)]
    }

    pub fn ycxcz_to_xyz(&self, ycxcz: [f32; 3]) -> [f32; 3] {
        let y = (ycxcz[0] + 16.0) / 116.0;
        let cx = ycxcz[1] / 500.0;
        let cz = ycxcz[2] / 200.0;
        [(y + cx) * self.white[0], y * self.white[1], (y - cz) * self.white[2]]
    }

    pub fn linear_rgb_to_ycxcz(&self, rgb: [f32; 3]) -> [f32; 3] {
        self.xyz_to_ycxcz(self.linear_rgb_to_xyz(rgb))
    }

    /// CIELAB relative to the D65 white.
    pub fn xyz_to_lab(&self, xyz: [f32; 3]) -> [f32; 3] {
        const DELTA: f32 = 6.0 / 29.0;
        let f = |t: f32| {
            if t > DELTA * DELTA * DELTA {
                t.powf(1.0 / 3.0)
            } else {
                t / (3.0 * DELTA * DELTA) + 4.0 / 29.0
            }
        };
        let fx = f(xyz[0] * self.inv_white[0]);
        let fy = f(xyz[1] * self.inv_white[1]);
        let fz = f(xyz[2] * self.inv_white[2]);
        [116.0 * fy - 16.0, 500.0 * (fx - fy), 200.0 * (fy - fz)]
    }

    /// The largest HyAB distance between Hunt-adjusted colours, reached between pure green and
    /// pure blue, raised to `qc`: FLIP's normaliser c_max.
    pub fn max_color_distance(&self, qc: f32) -> f32 {
        let green = hunt(self.xyz_to_lab(self.linear_rgb_to_xyz([0.0, 1.0, 0.0])));
        let blue = hunt(self.xyz_to_lab(self.linear_rgb_to_xyz([0.0, 0.0, 1.0])));
        hyab(green, blue).powf(qc)
    }
}

/// Hunt effect: chroma appears weaker at low luminance, so a and b are scaled by L/100.
pub fn hunt(lab: [f32; 3]) -> [f32; 3] {
    [lab[0], 0.01 * lab[0] * lab[1], 0.01 * lab[0] * lab[2]]
}

/// HyAB: city-block distance in lightness plus Euclidean distance in the chromatic plane,
/// better than ΔE for large colour differences.
pub fn hyab(a: [f32; 3], b: [f32; 3]) -> f32 {
    let dl = (a[0] - b[0]).abs();
    let da = a[1] - b[1];
    let db = a[2] - b[2];
    dl + (da * da + db * db).sqrt()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn white_is_lab_100_and_round_trips() {
        let cs = ColorSpace::default();
        let lab = cs.xyz_to_lab(cs.linear_rgb_to_xyz([1.0, 1.0, 1.0]));
        assert!(
            (lab[0] - 100.0).abs() < 1e-3 && lab[1].abs() < 1e-3 && lab[2].abs() < 1e-3,
            "{lab:?}"
        );
        assert!((cs.white[1] - 1.0).abs() < 1e-6);
        for rgb in [[0.2, 0.5, 0.9], [1.0, 0.0, 0.0], [0.01, 0.02, 0.0]] {
            let back = cs.xyz_to_linear_rgb(cs.ycxcz_to_xyz(cs.linear_rgb_to_ycxcz(rgb)));
            for c in 0..3 {
                assert!((back[c] - rgb[c]).abs() < 1e-4, "{rgb:?} -> {back:?}");
            }
        }
    }

    #[test]
    fn hyab_is_cityblock_plus_euclid() {
        assert_eq!(hyab([50.0, 0.0, 0.0], [40.0, 3.0, 4.0]), 15.0);
        // Hunt-adjusted green-blue distance is the largest pair among primaries.
        let cs = ColorSpace::default();
        let cmax = cs.max_color_distance(1.0);
        let prim =
            [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0], [1.0, 1.0, 1.0], [0.0, 0.0, 0.0]];
        for a in prim {
            for b in prim {
                let d = hyab(
                    hunt(cs.xyz_to_lab(cs.linear_rgb_to_xyz(a))),
                    hunt(cs.xyz_to_lab(cs.linear_rgb_to_xyz(b))),
                );
                assert!(d <= cmax + 1e-3, "{a:?} {b:?} {d} > {cmax}");
            }
        }
    }
}
