//! Track-length transmittance (delta tracking, Woodcock et al. 1965): 1 if a free flight
//! sampled by delta tracking leaves the segment, else 0. Unbiased; per-pixel variance (1 − T)T.

use crate::dda::Dda;
use crate::majorant_tracking::{MAX_COLLISIONS, next_collision};
use crate::medium::{Estimate, Medium, Segment};
use crate::rng::Pcg;

pub fn track_length(medium: &Medium, seg: &Segment, rng: &mut Pcg) -> Estimate {
    let mut dda = Dda::new(seg, medium.super_voxels.dims, medium.super_voxel_size());
    let mut t = seg.t0;
    let mut lookups = 0;
    while lookups < MAX_COLLISIONS {
        let Some((tc, majorant)) = next_collision(medium, &mut dda, t, rng) else { break };
        let mu = medium.mu(seg, tc, dda.ucell());
        lookups += 1;
        if rng.next_f32() < mu / majorant {
            return Estimate { value: 0.0, lookups };
        }
        t = tc;
    }
    Estimate { value: 1.0, lookups }
}
