//! Traversal of a regular grid along a segment (Amanatides & Woo 1987): the cells a ray crosses
//! in order, each with the parameter at which the ray leaves it. Used on the super-voxel grid
//! (cell = 16 voxels) by every estimator and on the voxel grid (cell = 1) by regular tracking.
//! Bounded: a segment crosses at most dims.x + dims.y + dims.z cells.

use glam::{IVec3, UVec3, Vec3};

use crate::medium::Segment;

#[derive(Clone, Copy, Debug)]
pub struct Dda {
    pub cell: IVec3,
    dims: IVec3,
    step: IVec3,
    /// Parameter at which the ray crosses the next cell boundary on each axis.
    t_next: Vec3,
    /// Parameter advance per cell on each axis.
    t_delta: Vec3,
    t_end: f32,
}

impl Dda {
    /// Starts at `seg.t0` in a grid of `dims` cells of `cell_size` texels each.
    pub fn new(seg: &Segment, dims: UVec3, cell_size: f32) -> Self {
        let o = seg.at(seg.t0) / cell_size;
        let d = seg.dir / cell_size;
        let dims_i = dims.as_ivec3();
        let cell = o.floor().as_ivec3().clamp(IVec3::ZERO, dims_i - IVec3::ONE);
        let step = IVec3::new(sign(d.x), sign(d.y), sign(d.z));
        let inv = d.abs().recip(); // inf on a zero component: never crosses that axis
        let boundary = cell.as_vec3() + step.max(IVec3::ZERO).as_vec3();
        let t_next = Vec3::new(
            cross_at(boundary.x, o.x, d.x, seg.t0),
            cross_at(boundary.y, o.y, d.y, seg.t0),
            cross_at(boundary.z, o.z, d.z, seg.t0),
        );
        Self { cell, dims: dims_i, step, t_next, t_delta: inv, t_end: seg.t1 }
    }

    /// Where the ray leaves the current cell (at most the segment's end).
    pub fn exit(&self) -> f32 {
        self.t_next.min_element().min(self.t_end)
    }

    /// The current cell as an unsigned index.
    pub fn ucell(&self) -> UVec3 {
        self.cell.as_uvec3()
    }

    /// Moves to the next cell; false when the segment ends first or the ray leaves the grid.
    pub fn advance(&mut self) -> bool {
        let t = self.t_next.min_element();
        if t >= self.t_end {
            return false;
        }
        // One axis per step (ties broken x, y, z): the same order as the WGSL twin.
        let axis = if self.t_next.x == t {
            0
        } else if self.t_next.y == t {
            1
        } else {
            2
        };
        self.cell[axis] += self.step[axis];
        self.t_next[axis] += self.t_delta[axis];
        self.cell[axis] >= 0 && self.cell[axis] < self.dims[axis]
    }
}

fn sign(x: f32) -> i32 {
    if x > 0.0 {
        1
    } else if x < 0.0 {
        -1
    } else {
        0
    }
}

fn cross_at(boundary: f32, o: f32, d: f32, t0: f32) -> f32 {
    if d == 0.0 { f32::INFINITY } else { t0 + (boundary - o) / d }
}
