//! The super-voxel grid (paper Sec. 4.2): one cell per 16³ voxels (the paper's size; any other
//! edge by `build_sized`: the paper fixes the explosion's bias with 12³, Sec. 6.3) with the minimum, maximum,
//! mean and RMS of (μ − μ_min) of its voxels. The maximum is the majorant of delta and ratio
//! tracking, the mean the importance of Kettunen et al.'s ray marching, the RMS of the excess
//! (Eq. 5) the importance of the variance-aware ray marching, the minimum its control variate.

use glam::UVec3;

use crate::density::DensityGrid;

/// Voxels per super-voxel edge by default (16³ voxels per super-voxel, as in the paper).
pub const SUPER_VOXEL: u32 = 16;

#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct SuperVoxel {
    pub min: f32,
    pub max: f32,
    pub mean: f32,
    /// RMS of (μ − μ_min) over the super-voxel's voxels (Eq. 5).
    pub rms_excess: f32,
}

impl SuperVoxel {
    /// Importance of the variance-aware sampling: Eq. 5, raised to a small non-zero floor in
    /// non-empty super-voxels (paper Sec. 4.3) so that Alg. 2's tight segment never cuts off a
    /// homogeneous super-voxel whose control variate must still be tracked.
    pub fn variance_importance(&self) -> f32 {
        if self.max > 0.0 { self.rms_excess.max(IMPORTANCE_FLOOR * self.max) } else { 0.0 }
    }
}

/// The floor of the variance-aware importance, relative to the super-voxel's maximum.
pub const IMPORTANCE_FLOOR: f32 = 1e-3;

#[derive(Clone, Debug, PartialEq)]
pub struct SuperVoxelGrid {
    pub dims: UVec3,
    /// Voxels per super-voxel edge.
    pub size: u32,
    /// x fastest, like the voxels.
    pub cells: Vec<SuperVoxel>,
}

impl SuperVoxelGrid {
    pub fn build(grid: &DensityGrid) -> Self {
        Self::build_sized(grid, SUPER_VOXEL)
    }

    /// Super-voxels of `size`³ voxels (size ≥ 1).
    pub fn build_sized(grid: &DensityGrid, size: u32) -> Self {
        assert!(size >= 1, "super-voxel size 0; expected at least 1 voxel per edge");
        let dims = (grid.res + UVec3::splat(size - 1)) / size;
        let mut cells = Vec::with_capacity((dims.x * dims.y * dims.z) as usize);
        for z in 0..dims.z {
            for y in 0..dims.y {
                for x in 0..dims.x {
                    let (lo, hi) = voxel_range(grid.res, size, UVec3::new(x, y, z));
                    cells.push(summarise(grid, lo, hi));
                }
            }
        }
        Self { dims, size, cells }
    }

    pub fn cell(&self, c: UVec3) -> &SuperVoxel {
        &self.cells[(c.x + self.dims.x * (c.y + self.dims.y * c.z)) as usize]
    }
}

/// The voxels [lo, hi] (inclusive) of super-voxel `c` (of `size`³ voxels) in a grid of `res`.
pub fn voxel_range(res: UVec3, size: u32, c: UVec3) -> (UVec3, UVec3) {
    let lo = c * size;
    (lo, (lo + UVec3::splat(size - 1)).min(res - UVec3::ONE))
}

fn summarise(grid: &DensityGrid, lo: UVec3, hi: UVec3) -> SuperVoxel {
    let voxels = || {
        (lo.z..=hi.z).flat_map(move |z| {
            (lo.y..=hi.y)
                .flat_map(move |y| (lo.x..=hi.x).map(move |x| grid.at(UVec3::new(x, y, z))))
        })
    };
    let count = voxels().count() as f64;
    let min = voxels().fold(f32::INFINITY, f32::min);
    let max = voxels().fold(0.0, f32::max);
    let mean = voxels().map(f64::from).sum::<f64>() / count;
    let ms = voxels().map(|m| f64::from(m - min).powi(2)).sum::<f64>() / count;
    SuperVoxel { min, max, mean: mean as f32, rms_excess: ms.sqrt() as f32 }
}
