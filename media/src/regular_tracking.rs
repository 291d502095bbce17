//! Regular tracking (Amanatides & Woo 1987): the exact optical depth of a segment through the
//! nearest-neighbour voxel grid, voxel by voxel. The reference the estimators are measured
//! against (bias maps, tests); not an estimator a method renders with.

use crate::dda::Dda;
use crate::medium::{Medium, Segment};

pub fn optical_depth(medium: &Medium, seg: &Segment) -> f64 {
    let mut dda = Dda::new(seg, medium.density.res, 1.0);
    let mut t = seg.t0;
    let mut tau = 0.0f64;
    loop {
        let exit = dda.exit();
        tau += f64::from(exit - t) * f64::from(medium.density.at(dda.ucell()));
        t = exit;
        if !dda.advance() {
            return tau;
        }
    }
}
