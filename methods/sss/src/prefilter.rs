//! Prefiltered irradiance MIPs and adaptive filtered importance sampling (AFIS, thesis Sec. 5.2,
//! eqs. 5.10-5.13, Algorithm 2); the twin of shaders/prefilter.wgsl.
//!
//! The irradiance is averaged 2x2 into a MIP chain each frame. A Burley sample reads the chain at
//! a level set by how much screen area the sample stands for: with n samples drawn from the
//! radial density, a sample at radius r covers A_s = 2πr / (n pdf(r)) texels, and eq. 5.12 reads
//! l = ½ max(log2(A_s / a), 0) with a = 1/16. The thesis writes the ratio in world units,
//! ℓ_max² t / (p n̂) with t the texels per unit area at the centre's depth; our radii and
//! densities are already in pixels (w of `SssFrame`), so that ratio is A_s itself.
//!
//! Departure: the 2x2 mean is over SSS texels only (weighted by the share of each child that is
//! SSS), and a texel with no SSS texel under it reads as the centre pixel, as level 0 does; the
//! thesis's chain averages every texel, which bleeds other surfaces into the profile.

/// The thesis's a of eq. 5.12 ("a = 1/16 gives a good balance between quality and performance").
pub const DEFAULT_A: f32 = 1.0 / 16.0;
/// Levels the chain keeps, level 0 included (the thesis generates 5 levels above the base).
pub const DEFAULT_LEVELS: u32 = 6;
/// The most levels a pass builds (a 2^7 footprint is wider than any profile on screen).
pub const MAX_LEVELS: u32 = 8;

/// AFIS's settings: eq. 5.12's a and how many levels the chain has (1 = no prefiltering).
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct Prefilter {
    pub a: f32,
    pub levels: u32,
}

impl Default for Prefilter {
    fn default() -> Self {
        Self { a: DEFAULT_A, levels: DEFAULT_LEVELS }
    }
}

impl Prefilter {
    pub fn validate(&self) -> Result<(), String> {
        if !(self.a > 0.0 && self.a.is_finite()) {
            return Err(format!(
                "prefilter a {}; expected a positive number (the thesis's 1/16)",
                self.a
            ));
        }
        if !(1..=MAX_LEVELS).contains(&self.levels) {
            return Err(format!("prefilter levels {}; expected 1 to {MAX_LEVELS}", self.levels));
        }
        Ok(())
    }
}

/// The size of level k of a width x height chain: halved, rounded up, at least 1.
pub fn level_size(width: u32, height: u32, k: u32) -> (u32, u32) {
    let (mut w, mut h) = (width, height);
    for _ in 0..k {
        (w, h) = (w.div_ceil(2).max(1), h.div_ceil(2).max(1));
    }
    (w, h)
}

/// Texels in levels 0..levels, i.e. where level `levels` would start in one buffer.
pub fn level_offset(width: u32, height: u32, levels: u32) -> u64 {
    (0..levels).map(|k| level_size(width, height, k)).map(|(w, h)| w as u64 * h as u64).sum()
}

/// Eq. 5.12 in pixels: the level for a sample at radius r (pixels) drawn with the radial density
/// `pdf_r` (per pixel of radius) as one of n, clamped to the chain's top level.
pub fn level(r: f32, pdf_r: f32, n: u32, a: f32, levels: u32) -> f32 {
    // Texels per sample: 1 / (n × the density per unit area, pdf_r / 2πr).
    let texels = (2.0 * std::f32::consts::PI * r / (n as f32 * pdf_r)).max(1e-30);
    (0.5 * (texels / a).log2()).clamp(0.0, (levels - 1) as f32)
}

/// The chain: level k holds (mean irradiance of its SSS texels, share of SSS texels) per texel.
#[derive(Clone, Debug, PartialEq)]
pub struct MipChain {
    pub width: u32,
    pub height: u32,
    pub levels: Vec<Vec<[f32; 4]>>,
}

impl MipChain {
    /// Builds `levels` levels from (rgb, w) texels; w > 0 marks an SSS texel.
    pub fn build(width: u32, height: u32, irradiance: &[[f32; 4]], levels: u32) -> Self {
        let base: Vec<[f32; 4]> = irradiance
            .iter()
            .map(|t| if t[3] > 0.0 { [t[0], t[1], t[2], 1.0] } else { [0.0; 4] })
            .collect();
        let mut chain = vec![base];
        for k in 1..levels {
            let (pw, ph) = level_size(width, height, k - 1);
            let (w, h) = level_size(width, height, k);
            let prev = &chain[k as usize - 1];
            let next = (0..h)
                .flat_map(|y| (0..w).map(move |x| (x, y)))
                .map(|(x, y)| {
                    let children = [(0, 0), (1, 0), (0, 1), (1, 1)].map(|(dx, dy)| {
                        let (cx, cy) = (2 * x + dx, 2 * y + dy);
                        if cx < pw && cy < ph { prev[(cy * pw + cx) as usize] } else { [0.0; 4] }
                    });
                    mean_of_covered(&children)
                })
                .collect();
            chain.push(next);
        }
        Self { width, height, levels: chain }
    }

    /// Bilinear at q (level-0 pixels, texel centres at +0.5) on level k; texels with no SSS
    /// texel under them read as `centre`.
    pub fn fetch_level(&self, k: u32, q: [f32; 2], centre: [f32; 3]) -> [f32; 3] {
        let (w, h) = level_size(self.width, self.height, k);
        let (w, h) = (w as i32, h as i32);
        let scale = 1.0 / (1u32 << k) as f32;
        let level = &self.levels[k as usize];
        bilinear(w, h, [q[0] * scale, q[1] * scale], |i, j| {
            let t = level[(j * w + i) as usize];
            if t[3] > 0.0 { [t[0], t[1], t[2]] } else { centre }
        })
    }

    /// Trilinear: between levels floor(l) and floor(l) + 1.
    pub fn fetch(&self, l: f32, q: [f32; 2], centre: [f32; 3]) -> [f32; 3] {
        let k0 = l.floor() as u32;
        let f = l - k0 as f32;
        let a = self.fetch_level(k0, q, centre);
        if f <= 0.0 {
            return a;
        }
        let b = self.fetch_level((k0 + 1).min(self.levels.len() as u32 - 1), q, centre);
        std::array::from_fn(|i| a[i] + f * (b[i] - a[i]))
    }
}

/// Bilinear at q (texel centres at +0.5) over a w x h grid of `texel(i, j)`, indices clamped to
/// the grid: the fetch of level 0 (`screen_pass`) and of every MIP level.
pub(crate) fn bilinear(
    w: i32,
    h: i32,
    q: [f32; 2],
    texel: impl Fn(i32, i32) -> [f32; 3],
) -> [f32; 3] {
    let (x, y) = (q[0] - 0.5, q[1] - 0.5);
    let (x0, y0) = (x.floor(), y.floor());
    let (fx, fy) = (x - x0, y - y0);
    let at = |i: i32, j: i32| texel(i.clamp(0, w - 1), j.clamp(0, h - 1));
    // Clamp before the cast: radii in the far tail are huge.
    let (xi, yi) = (x0.clamp(-2.0, w as f32 + 1.0) as i32, y0.clamp(-2.0, h as f32 + 1.0) as i32);
    let (a, b, c, d) = (at(xi, yi), at(xi + 1, yi), at(xi, yi + 1), at(xi + 1, yi + 1));
    std::array::from_fn(|i| {
        (1.0 - fy) * ((1.0 - fx) * a[i] + fx * b[i]) + fy * ((1.0 - fx) * c[i] + fx * d[i])
    })
}

/// The 2x2 mean over SSS texels: Σ s·L / Σ s, with share Σ s / 4 (s = each child's share).
fn mean_of_covered(children: &[[f32; 4]; 4]) -> [f32; 4] {
    let s: f32 = children.iter().map(|c| c[3]).sum();
    if s <= 0.0 {
        return [0.0; 4];
    }
    let m = |i: usize| children.iter().map(|c| c[3] * c[i]).sum::<f32>() / s;
    [m(0), m(1), m(2), 0.25 * s]
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn sizes_halve_rounding_up_and_offsets_add_up() {
        assert_eq!(level_size(7, 3, 0), (7, 3));
        assert_eq!(level_size(7, 3, 1), (4, 2));
        assert_eq!(level_size(7, 3, 2), (2, 1));
        assert_eq!(level_size(7, 3, 3), (1, 1));
        assert_eq!(level_offset(7, 3, 3), 21 + 8 + 2);
    }

    #[test]
    fn the_mean_is_over_sss_texels_only() {
        // A 2x2 image: three SSS texels and one other surface (w = 0), which must not bleed in.
        let img = [
            [1.0, 2.0, 3.0, 1.0],
            [3.0, 2.0, 1.0, 0.5],
            [100.0, 100.0, 100.0, 0.0],
            [2.0, 2.0, 2.0, 2.0],
        ];
        let chain = MipChain::build(2, 2, &img, 2);
        assert_eq!(chain.levels[1], vec![[2.0, 2.0, 2.0, 0.75]]);
        // A texel with no SSS under it reads as the centre.
        let none = MipChain::build(2, 2, &[[5.0, 5.0, 5.0, 0.0]; 4], 2);
        assert_eq!(none.fetch_level(1, [1.0, 1.0], [0.5; 3]), [0.5; 3]);
    }

    #[test]
    fn the_level_follows_the_area_per_sample() {
        // A sample that stands for a·4^k texels reads level k.
        let a = DEFAULT_A;
        for k in 0..4 {
            let texels = a * 4f32.powi(k);
            let (r, n) = (3.0, 16);
            let pdf_r = 2.0 * std::f32::consts::PI * r / (n as f32 * texels);
            assert!((level(r, pdf_r, n, a, 8) - k as f32).abs() < 1e-5, "k = {k}");
        }
        // The centre (r = 0) reads level 0; the top clamps.
        assert_eq!(level(0.0, 0.5, 64, a, 6), 0.0);
        assert_eq!(level(1e6, 1e-9, 8, a, 6), 5.0);
    }
}
