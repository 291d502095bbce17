// Track-length and ratio tracking against the super-voxel majorants (media::track_length,
// media::ratio_tracking, media::majorant_tracking).

import package::media::types::{RaySegment};
import package::media::media_rng::{media_rand};
import package::media::media_grid::{media_dims, media_res, voxel_density, BIG, super_voxel_size, mu_at, super_voxel};
import package::media::media_dda::{Dda, dda_advance, dda_exit, dda_new};

const MAX_COLLISIONS: u32 = 1024u;

// The next tentative collision after t, or t = BIG when the segment ends first; .y = majorant.
fn next_collision(s: RaySegment, dda: ptr<function, Dda>, t_start: f32, rng: ptr<function, u32>) -> vec2f {
    var target_depth = -log(1.0 - media_rand(rng));
    var t = t_start;
    let bound = u32((*dda).dims.x + (*dda).dims.y + (*dda).dims.z) + 1u;
    for (var i = 0u; i < bound; i++) {
        let majorant = super_voxel((*dda).cell).y;
        let exit = dda_exit(*dda);
        let depth = (exit - t) * majorant;
        if depth > target_depth {
            return vec2f(t + target_depth / majorant, majorant);
        }
        target_depth -= depth;
        t = exit;
        if !dda_advance(dda) {
            break;
        }
    }
    return vec2f(BIG, 0.0);
}

// The track-length estimate: 1 when delta tracking leaves the segment without a real collision.
fn track_length(s: RaySegment, rng: ptr<function, u32>) -> f32 {
    return select(0.0, 1.0, delta_tracking(s, rng) == BIG);
}

fn ratio_tracking(s: RaySegment, rng: ptr<function, u32>) -> f32 {
    var dda = dda_new(s, media_dims(), f32(super_voxel_size()));
    var t = s.t0;
    var value = 1.0;
    for (var n = 0u; n < MAX_COLLISIONS; n++) {
        let c = next_collision(s, &dda, t, rng);
        if c.x == BIG {
            break;
        }
        value *= 1.0 - mu_at(s, c.x, dda.cell) / c.y;
        t = c.x;
    }
    return value;
}

// Delta tracking (free-flight sampling, density T(t) μ(t)): the parameter of the first real
// collision on the segment, or BIG when the ray leaves it. The same walk as track_length.
fn delta_tracking(s: RaySegment, rng: ptr<function, u32>) -> f32 {
    var dda = dda_new(s, media_dims(), f32(super_voxel_size()));
    var t = s.t0;
    for (var n = 0u; n < MAX_COLLISIONS; n++) {
        let c = next_collision(s, &dda, t, rng);
        if c.x == BIG {
            break;
        }
        let mu = mu_at(s, c.x, dda.cell);
        if media_rand(rng) < mu / c.y {
            return c.x;
        }
        t = c.x;
    }
    return BIG;
}

// Regular tracking (media::regular_tracking): the exact optical depth of the segment through
// the nearest-neighbour voxels, voxel by voxel (not an estimator; no lookups counted).
fn regular_tracking(s: RaySegment) -> f32 {
    let res = media_res();
    var dda = dda_new(s, res, 1.0);
    var t = s.t0;
    var tau = 0.0;
    let bound = res.x + res.y + res.z + 1u;
    for (var n = 0u; n < bound; n++) {
        let exit = dda_exit(dda);
        tau += (exit - t) * voxel_density(vec3u(dda.cell));
        t = exit;
        if !dda_advance(&dda) {
            break;
        }
    }
    return tau;
}
