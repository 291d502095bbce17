//! Ratio tracking (Novák et al. 2014): the product of the null-collision probabilities
//! 1 − μ/μ̂ over the tentative collisions of the segment. Unbiased, in [0, 1].

use crate::dda::Dda;
use crate::majorant_tracking::{MAX_COLLISIONS, next_collision};
use crate::medium::{Estimate, Medium, Segment};
use crate::rng::Pcg;

pub fn ratio_tracking(medium: &Medium, seg: &Segment, rng: &mut Pcg) -> Estimate {
    let mut dda = Dda::new(seg, medium.super_voxels.dims, medium.super_voxel_size());
    let mut t = seg.t0;
    let mut value = 1.0;
    let mut lookups = 0;
    while lookups < MAX_COLLISIONS {
        let Some((tc, majorant)) = next_collision(medium, &mut dda, t, rng) else { break };
        value *= 1.0 - medium.mu(seg, tc, dda.ucell()) / majorant;
        lookups += 1;
        t = tc;
    }
    Estimate { value, lookups }
}
