//! Voxel density grids (extinction μ per world unit, one value per voxel, looked up with
//! nearest-neighbour interpolation) and the procedural fields they are baked from.
//!
//! Departure from the paper: it jitters each lookup stochastically (stochastic texture
//! filtering); we use nearest-neighbour lookups, so a voxel's extinction is piecewise constant
//! and regular tracking gives exact optical depths (the reference of the bias maps and tests).

use glam::{UVec3, Vec3};
use noise::{Fbm, MultiFractal, NoiseFn, Perlin};

use crate::mesh_inside::MeshInside;

pub use scene::DensityKind;

#[derive(Clone, Debug, PartialEq)]
pub struct DensityGrid {
    pub res: UVec3,
    /// μ per voxel, x fastest.
    pub data: Vec<f32>,
    pub box_min: Vec3,
    pub box_max: Vec3,
}

impl DensityGrid {
    /// Bakes `kind` at the voxel centres of a `res` grid filling [box_min, box_max], peak
    /// extinction `sigma_t`.
    pub fn bake(
        kind: &DensityKind,
        res: UVec3,
        sigma_t: f32,
        box_min: Vec3,
        box_max: Vec3,
    ) -> Self {
        Self::bake_spun(kind, res, sigma_t, box_min, box_max, 0.0)
    }

    /// [`Self::bake`] with the field turned by `spin` radians about the box's vertical axis
    /// (an animated medium; the field is looked up at the voxel centre turned back).
    pub fn bake_spun(
        kind: &DensityKind,
        res: UVec3,
        sigma_t: f32,
        box_min: Vec3,
        box_max: Vec3,
        spin: f32,
    ) -> Self {
        Self::bake_bounded(kind, None, res, sigma_t, box_min, box_max, spin)
    }

    /// [`Self::bake_spun`] clipped to a closed mesh in the box's unit coordinates: a voxel whose
    /// centre lies outside it is empty (so the boundary is resolved to a voxel; the super-voxel
    /// grid then skips what lies outside). The mesh turns with the field.
    pub fn bake_bounded(
        kind: &DensityKind,
        bound: Option<&MeshInside>,
        res: UVec3,
        sigma_t: f32,
        box_min: Vec3,
        box_max: Vec3,
        spin: f32,
    ) -> Self {
        let mut data = Vec::with_capacity((res.x * res.y * res.z) as usize);
        let field = Field::new(kind);
        let turn = glam::Quat::from_rotation_y(-spin);
        for z in 0..res.z {
            for y in 0..res.y {
                for x in 0..res.x {
                    let mut p = (UVec3::new(x, y, z).as_vec3() + 0.5) / res.as_vec3();
                    if spin != 0.0 {
                        p = turn * (p - Vec3::splat(0.5)) + Vec3::splat(0.5);
                    }
                    let inside = bound.is_none_or(|m| m.contains(p));
                    data.push(if inside { sigma_t * field.unit_density(p) } else { 0.0 });
                }
            }
        }
        Self { res, data, box_min, box_max }
    }

    pub fn voxel_size(&self) -> Vec3 {
        (self.box_max - self.box_min) / self.res.as_vec3()
    }

    pub fn index(&self, v: UVec3) -> usize {
        (v.x + self.res.x * (v.y + self.res.y * v.z)) as usize
    }

    pub fn at(&self, v: UVec3) -> f32 {
        self.data[self.index(v)]
    }

    /// μ at texel-space point `p`, its voxel clamped into [lo, hi] (the voxels of the
    /// super-voxel the caller is in, so that a point on a boundary never reads a neighbour whose
    /// value lies outside that super-voxel's bounds).
    pub fn lookup(&self, p: Vec3, lo: UVec3, hi: UVec3) -> f32 {
        let v = p.floor().max(Vec3::ZERO).as_uvec3().clamp(lo, hi);
        self.at(v)
    }

    pub fn max(&self) -> f32 {
        self.data.iter().copied().fold(0.0, f32::max)
    }
}

/// A procedural field on the unit cube with values in [0, 1].
enum Field {
    Constant,
    Cloud(Fbm<Perlin>),
    Explosion(Perlin, f64),
    Grid(scene::RawGrid),
}

impl Field {
    fn new(kind: &DensityKind) -> Self {
        match *kind {
            DensityKind::Homogeneous => Field::Constant,
            DensityKind::Cloud { octaves, frequency, seed } => {
                Field::Cloud(Fbm::<Perlin>::new(seed).set_octaves(octaves).set_frequency(frequency))
            }
            DensityKind::Explosion { frequency, seed } => {
                Field::Explosion(Perlin::new(seed), frequency)
            }
            // Checked when the scenario loaded (sim::Scenario, errors at the grid file's line).
            DensityKind::Grid { ref file } => {
                Field::Grid(scene::RawGrid::load(file).unwrap_or_else(|e| panic!("{e}")))
            }
        }
    }

    fn unit_density(&self, p: Vec3) -> f32 {
        let r = (p - Vec3::splat(0.5)).length() * 2.0; // 0 at the centre, 1 at the faces
        let q = [p.x as f64, p.y as f64, p.z as f64];
        match self {
            Field::Constant => 1.0,
            Field::Grid(g) => g.at_unit(p.to_array()),
            Field::Cloud(fbm) => {
                // Sphere of radius 0.8 with a soft edge, eroded by the noise.
                let shape = 1.0 - r / 0.8;
                let n = fbm.get(q) as f32;
                (1.6 * shape + 0.9 * n).clamp(0.0, 1.0)
            }
            Field::Explosion(perlin, frequency) => {
                // Shell 0.5 < r < 0.8; inside it only the crests of high-frequency noise.
                if !(0.5..0.8).contains(&r) {
                    return 0.0;
                }
                let n = perlin.get(q.map(|c| c * frequency)) as f32;
                if n > 0.35 { 1.0 } else { 0.0 }
            }
        }
    }
}

impl DensityGrid {
    /// A scenario's medium, baked.
    pub fn from_desc(desc: &scene::MediumDesc) -> Self {
        Self::from_state(
            desc,
            &scene::MediumState {
                box_min: desc.box_min,
                box_max: desc.box_max,
                sigma_t: desc.sigma_t,
                spin: 0.0,
            },
        )
    }

    /// An animated medium at one of its states (`MediumDesc::at`), clipped to its bound.
    pub fn from_state(desc: &scene::MediumDesc, s: &scene::MediumState) -> Self {
        Self::from_state_within(desc, s, Self::bound_of(desc).as_ref())
    }

    /// The inside test of a medium's mesh bound (None for its box). The mesh lies in the box's
    /// unit coordinates, so one test serves every state of an animated medium.
    pub fn bound_of(desc: &scene::MediumDesc) -> Option<MeshInside> {
        // Checked when the scenario loaded (sim::Scenario, errors at the mesh file's line).
        let mesh = desc
            .bound
            .mesh(desc.box_min, desc.box_max)
            .unwrap_or_else(|e| panic!("medium '{}': {e}", desc.name));
        mesh.as_ref().map(MeshInside::new)
    }

    /// `from_state` with the bound's inside test already built (`bound_of`).
    pub fn from_state_within(
        desc: &scene::MediumDesc,
        s: &scene::MediumState,
        inside: Option<&MeshInside>,
    ) -> Self {
        let (x, y, z) = desc.resolution;
        Self::bake_bounded(
            &desc.kind,
            inside,
            UVec3::new(x, y, z),
            s.sigma_t,
            s.box_min,
            s.box_max,
            s.spin,
        )
    }
}
