//! Participating media as a scenario declares them (`media: [...]`): a box, a procedural
//! density baked to a voxel grid, albedo and optional emission. Plain data; the `media` crate
//! bakes and renders them.

use glam::Vec3;
use serde::{Deserialize, Serialize};

/// The procedural field a medium is baked from.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub enum DensityKind {
    /// μ = `sigma_t` everywhere in the box.
    Homogeneous,
    /// A round cloud: fBm (Perlin, `octaves`, base frequency `frequency` per box) eroding a
    /// sphere, scaled to peak `sigma_t`.
    Cloud { octaves: usize, frequency: f64, seed: u32 },
    /// The paper's failure case: a thin shell of sparse, high-frequency blobs (most voxels
    /// empty, the rest at `sigma_t`), so that few samples along a ray see any density.
    Explosion { frequency: f64, seed: u32 },
    /// A raw density grid file ([`RawGrid`]; a relative path is resolved against the scenario's
    /// folder), looked up nearest-neighbour and scaled to peak `sigma_t`.
    Grid { file: std::path::PathBuf },
}

/// A raw density grid file, text so that a bad value has a line:
///
/// ```text
/// # comments start with '#'
/// density_grid NX NY NZ
/// v v v ...      NX·NY·NZ values in [0, 1], x fastest, then y, then z, any number per line
/// ```
#[derive(Clone, Debug, PartialEq)]
pub struct RawGrid {
    pub res: (u32, u32, u32),
    pub data: Vec<f32>,
}

impl RawGrid {
    /// The largest grid a file may hold per axis.
    pub const MAX_RES: u32 = 256;

    pub fn load(path: &std::path::Path) -> Result<RawGrid, String> {
        let text = std::fs::read_to_string(path)
            .map_err(|e| format!("{}: cannot read the density grid: {e}", path.display()))?;
        Self::parse(&text, &path.display().to_string())
    }

    /// Parses `text`; errors read `FILE:LINE: what was found, what was expected`.
    pub fn parse(text: &str, file: &str) -> Result<RawGrid, String> {
        let mut res = None;
        let mut data = Vec::new();
        let mut last_line = 0;
        for (i, line) in text.lines().enumerate() {
            let n = i + 1;
            last_line = n;
            let line = line.split('#').next().unwrap_or("").trim();
            if line.is_empty() {
                continue;
            }
            let Some((x, y, z)) = res else {
                let words: Vec<&str> = line.split_whitespace().collect();
                let dims: Vec<Option<u32>> = words.iter().skip(1).map(|w| w.parse().ok()).collect();
                match (words.first(), dims.as_slice()) {
                    (Some(&"density_grid"), [Some(x), Some(y), Some(z)])
                        if [*x, *y, *z].iter().all(|&r| (1..=Self::MAX_RES).contains(&r)) =>
                    {
                        res = Some((*x, *y, *z))
                    }
                    _ => {
                        return Err(format!(
                            "{file}:{n}: found '{line}'; expected the header 'density_grid NX NY NZ' with each size 1 to {}",
                            Self::MAX_RES
                        ));
                    }
                }
                continue;
            };
            for word in line.split_whitespace() {
                match word.parse::<f32>() {
                    Ok(v) if v.is_finite() && (0.0..=1.0).contains(&v) => data.push(v),
                    _ => {
                        return Err(format!(
                            "{file}:{n}: found '{word}'; expected a density in [0, 1]"
                        ));
                    }
                }
                if data.len() as u64 > u64::from(x) * u64::from(y) * u64::from(z) {
                    return Err(format!(
                        "{file}:{n}: more than the {x}x{y}x{z} = {} values of the header",
                        x * y * z
                    ));
                }
            }
        }
        let Some((x, y, z)) = res else {
            return Err(format!(
                "{file}:{}: no header; expected 'density_grid NX NY NZ'",
                last_line.max(1)
            ));
        };
        if data.len() as u64 != u64::from(x) * u64::from(y) * u64::from(z) {
            return Err(format!(
                "{file}:{last_line}: {} values; expected {x}x{y}x{z} = {}",
                data.len(),
                x * y * z
            ));
        }
        Ok(RawGrid { res: (x, y, z), data })
    }

    /// The value of the voxel holding unit-cube point `p` (nearest neighbour).
    pub fn at_unit(&self, p: [f32; 3]) -> f32 {
        let (x, y, z) = self.res;
        let i = |c: f32, r: u32| ((c * r as f32).floor().max(0.0) as u32).min(r - 1);
        let (a, b, c) = (i(p[0], x), i(p[1], y), i(p[2], z));
        self.data[(a + x * (b + y * c)) as usize]
    }
}

/// One medium of a scenario.
#[derive(Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct MediumDesc {
    pub name: String,
    pub kind: DensityKind,
    pub box_min: Vec3,
    pub box_max: Vec3,
    /// A closed mesh the medium is clipped to inside its box (`MediumBound::Box`, none, by
    /// default).
    #[serde(default, skip_serializing_if = "is_box")]
    pub bound: crate::MediumBound,
    /// Peak extinction per world unit.
    pub sigma_t: f32,
    /// Voxels along each axis of the box.
    #[serde(default = "default_resolution")]
    pub resolution: (u32, u32, u32),
    /// Single-scattering albedo (σ_s / σ_t), per channel.
    #[serde(default = "default_albedo")]
    pub albedo: Vec3,
    /// Emitted radiance per unit extinction, if any.
    #[serde(default)]
    pub emission: Option<Vec3>,
    /// How the medium moves and changes over time (none by default).
    #[serde(default, skip_serializing_if = "MediumMotion::is_still")]
    pub motion: MediumMotion,
    /// Voxels per super-voxel edge of its majorant and importance grid (16, the paper's; it
    /// fixes the sparse explosion's bias with 12).
    #[serde(default = "default_super_voxel", skip_serializing_if = "is_default_super_voxel")]
    pub super_voxel: u32,
}

/// A medium's animation, a function of the simulated time t (seconds): its box moves at
/// `velocity` and scales about its centre by 1 + `scale_per_second` t, its density field turns
/// about the box's vertical axis at `spin_degrees_per_second` (the field is rebaked turned inside
/// the fixed box: a shear where the box is not square in x and z), and its extinction pulses as
/// sigma_t (1 + `pulse_amplitude` sin(2π t / `pulse_period`)).
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct MediumMotion {
    pub velocity: Vec3,
    pub scale_per_second: f32,
    pub spin_degrees_per_second: f32,
    pub pulse_amplitude: f32,
    pub pulse_period: f32,
}

impl MediumMotion {
    pub fn is_still(&self) -> bool {
        *self == Self::default()
    }
}

/// A medium at one time: its box, peak extinction and field rotation (radians about y).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct MediumState {
    pub box_min: Vec3,
    pub box_max: Vec3,
    pub sigma_t: f32,
    pub spin: f32,
}

/// Voxels per super-voxel edge unless a medium says otherwise (the paper's 16).
pub const DEFAULT_SUPER_VOXEL: u32 = 16;

fn default_super_voxel() -> u32 {
    DEFAULT_SUPER_VOXEL
}

fn is_default_super_voxel(s: &u32) -> bool {
    *s == DEFAULT_SUPER_VOXEL
}

fn is_box(b: &crate::MediumBound) -> bool {
    *b == crate::MediumBound::Box
}

/// As derived, but `bound` only when it is not the box and `super_voxel` only when not 16: the
/// reference cache hashes a medium by its `Debug` form, and a field must not change the keys of
/// media declared before it.
impl std::fmt::Debug for MediumDesc {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        let mut d = f.debug_struct("MediumDesc");
        d.field("name", &self.name)
            .field("kind", &self.kind)
            .field("box_min", &self.box_min)
            .field("box_max", &self.box_max);
        if !is_box(&self.bound) {
            d.field("bound", &self.bound);
        }
        d.field("sigma_t", &self.sigma_t)
            .field("resolution", &self.resolution)
            .field("albedo", &self.albedo)
            .field("emission", &self.emission)
            .field("motion", &self.motion);
        if !is_default_super_voxel(&self.super_voxel) {
            d.field("super_voxel", &self.super_voxel);
        }
        d.finish()
    }
}

fn default_resolution() -> (u32, u32, u32) {
    (64, 64, 64)
}

fn default_albedo() -> Vec3 {
    Vec3::splat(0.8)
}

/// The largest resolution along an axis a scenario may ask for (the grid is baked on load).
pub const MAX_MEDIUM_RESOLUTION: u32 = 512;

impl MediumDesc {
    /// What is wrong with the declaration, if anything (the caller adds the file and line).
    pub fn problem(&self) -> Option<String> {
        let (x, y, z) = self.resolution;
        if !(self.box_min.cmplt(self.box_max).all()) {
            return Some(format!(
                "medium '{}': box_min {} must be below box_max {} on every axis",
                self.name, self.box_min, self.box_max
            ));
        }
        if !(self.sigma_t.is_finite() && self.sigma_t >= 0.0) {
            return Some(format!(
                "medium '{}': sigma_t {} must be a finite extinction >= 0",
                self.name, self.sigma_t
            ));
        }
        if [x, y, z].iter().any(|&r| r == 0 || r > MAX_MEDIUM_RESOLUTION) {
            return Some(format!(
                "medium '{}': resolution ({x}, {y}, {z}) must be 1 to {MAX_MEDIUM_RESOLUTION} voxels per axis",
                self.name
            ));
        }
        if !(self.albedo.cmpge(Vec3::ZERO).all() && self.albedo.cmple(Vec3::ONE).all()) {
            return Some(format!(
                "medium '{}': albedo {} must lie in [0, 1]",
                self.name, self.albedo
            ));
        }
        if self.super_voxel == 0 {
            return Some(format!(
                "medium '{}': super_voxel 0; expected at least 1 voxel per super-voxel edge (16 by default)",
                self.name
            ));
        }
        let m = &self.motion;
        if !(m.velocity.is_finite()
            && m.scale_per_second.is_finite()
            && m.spin_degrees_per_second.is_finite())
        {
            return Some(format!(
                "medium '{}': motion velocity, scale_per_second and spin_degrees_per_second must be finite",
                self.name
            ));
        }
        if !(0.0..1.0).contains(&m.pulse_amplitude)
            || (m.pulse_amplitude > 0.0 && !(m.pulse_period.is_finite() && m.pulse_period > 0.0))
        {
            return Some(format!(
                "medium '{}': motion pulse_amplitude {} must lie in [0, 1) and pulse_period {} must be > 0 where it pulses",
                self.name, m.pulse_amplitude, m.pulse_period
            ));
        }
        if let Some(e) = self.emission
            && !(e.is_finite() && e.cmpge(Vec3::ZERO).all())
        {
            return Some(format!("medium '{}': emission {e} must be finite and >= 0", self.name));
        }
        None
    }

    /// The medium at simulated time `t` (seconds); a still medium is its declaration.
    pub fn at(&self, t: f32) -> MediumState {
        let m = &self.motion;
        let centre = 0.5 * (self.box_min + self.box_max) + m.velocity * t;
        // Never inverted or collapsed: a shrinking box stops at 1% of its size.
        let half = 0.5 * (self.box_max - self.box_min) * (1.0 + m.scale_per_second * t).max(0.01);
        let pulse = if m.pulse_amplitude > 0.0 {
            1.0 + m.pulse_amplitude * (std::f32::consts::TAU * t / m.pulse_period).sin()
        } else {
            1.0
        };
        if m.is_still() {
            return MediumState {
                box_min: self.box_min,
                box_max: self.box_max,
                sigma_t: self.sigma_t,
                spin: 0.0,
            };
        }
        MediumState {
            box_min: centre - half,
            box_max: centre + half,
            sigma_t: self.sigma_t * pulse,
            spin: m.spin_degrees_per_second.to_radians() * t,
        }
    }
}
