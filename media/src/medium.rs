//! A medium on the CPU: its voxel density grid, the super-voxel grid built from it, and the
//! segment of a ray that crosses its box, in the grid's texel space (one unit = one voxel) with
//! the ray parameter t kept in world units, so extinctions stay per world unit.

use glam::Vec3;

use crate::density::DensityGrid;
use crate::supervoxel::SuperVoxelGrid;

pub struct Medium {
    pub density: DensityGrid,
    pub super_voxels: SuperVoxelGrid,
}

/// A ray inside a medium's box: texel-space origin and direction (`dir` = world direction /
/// voxel size, so that t is a world distance) and the parameter range [t0, t1] inside the box.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Segment {
    pub origin: Vec3,
    pub dir: Vec3,
    pub t0: f32,
    pub t1: f32,
}

impl Segment {
    pub fn at(&self, t: f32) -> Vec3 {
        self.origin + self.dir * t
    }

    pub fn length(&self) -> f32 {
        self.t1 - self.t0
    }
}

impl Medium {
    pub fn new(density: DensityGrid) -> Self {
        let super_voxels = SuperVoxelGrid::build(&density);
        Self { density, super_voxels }
    }

    /// With super-voxels of `size`³ voxels (the paper's 16 by `new`).
    pub fn with_super_voxel(density: DensityGrid, size: u32) -> Self {
        let super_voxels = SuperVoxelGrid::build_sized(&density, size);
        Self { density, super_voxels }
    }

    /// The super-voxel edge in voxels, as the traversals' cell size.
    pub fn super_voxel_size(&self) -> f32 {
        self.super_voxels.size as f32
    }

    /// The part of the world-space ray (origin, unit direction) in [0, t_max] inside the box,
    /// or None when it misses.
    pub fn segment(&self, origin: Vec3, dir: Vec3, t_max: f32) -> Option<Segment> {
        let g = &self.density;
        let voxel = g.voxel_size();
        let o = (origin - g.box_min) / voxel;
        let d = dir / voxel;
        let res = g.res.as_vec3();
        // Slab test in texel space; a zero component divides to ±inf, which the min/max keep.
        let inv = d.recip();
        let a = (Vec3::ZERO - o) * inv;
        let b = (res - o) * inv;
        let t0 = a.min(b).max_element().max(0.0);
        let t1 = a.max(b).min_element().min(t_max);
        (t0 < t1).then_some(Segment { origin: o, dir: d, t0, t1 })
    }
}

impl Medium {
    /// μ at parameter t, inside super-voxel `cell` (the DDA's current one).
    pub fn mu(&self, seg: &Segment, t: f32, cell: glam::UVec3) -> f32 {
        let (lo, hi) =
            crate::supervoxel::voxel_range(self.density.res, self.super_voxels.size, cell);
        self.density.lookup(seg.at(t), lo, hi)
    }
}

/// An estimate and what it cost: density lookups of the voxel grid (super-voxel reads not
/// counted, as in the paper's sample counts).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Estimate {
    pub value: f32,
    pub lookups: u32,
}
