//! Free-flight sampling against the super-voxel majorants (the maximum of each super-voxel):
//! the tentative collisions that delta tracking accepts or rejects and ratio tracking weighs.

use crate::dda::Dda;
use crate::medium::Medium;
use crate::rng::Pcg;

/// Tentative collisions per estimate at most (GPU loops must stay bounded, ARCHITECTURE.md);
/// beyond it the estimator stops as if the ray had left the medium. Reached only where the
/// majorant optical depth of a segment exceeds about 900.
pub const MAX_COLLISIONS: u32 = 1024;

/// The next tentative collision after `t`, with the majorant there; None when the segment ends
/// first. Consumes one random number.
pub fn next_collision(medium: &Medium, dda: &mut Dda, t: f32, rng: &mut Pcg) -> Option<(f32, f32)> {
    let mut target = -(1.0 - rng.next_f32()).ln();
    let mut t = t;
    loop {
        let majorant = medium.super_voxels.cell(dda.ucell()).max;
        let exit = dda.exit();
        let depth = (exit - t) * majorant;
        if depth > target {
            return Some((t + target / majorant, majorant));
        }
        target -= depth;
        t = exit;
        if !dda.advance() {
            return None;
        }
    }
}
