// Grid traversal along a segment (Amanatides & Woo), the twin of media::dda::Dda: one axis per
// step, ties broken x, y, z. A segment crosses at most dims.x + dims.y + dims.z cells.

import package::media::types::{RaySegment};
import package::media::media_grid::{BIG, seg_at};

struct Dda {
    cell: vec3i,
    dims: vec3i,
    step: vec3i,
    t_next: vec3f,
    t_delta: vec3f,
    t_end: f32,
}

fn dda_new(s: RaySegment, dims: vec3u, cell_size: f32) -> Dda {
    let o = seg_at(s, s.t0) / cell_size;
    let d = s.dir / cell_size;
    let di = vec3i(dims);
    let cell = clamp(vec3i(floor(o)), vec3i(0), di - vec3i(1));
    let step = vec3i(sign(d));
    let moving = d != vec3f(0.0);
    let inv = select(vec3f(BIG), 1.0 / abs(d), moving);
    let boundary = vec3f(cell) + vec3f(max(step, vec3i(0)));
    let t_next = select(vec3f(BIG), s.t0 + (boundary - o) / d, moving);
    return Dda(cell, di, step, t_next, inv, s.t1);
}

fn dda_exit(dda: Dda) -> f32 {
    return min(min(min(dda.t_next.x, dda.t_next.y), dda.t_next.z), dda.t_end);
}

// Moves to the next cell; false when the segment ends first or the ray leaves the grid.
fn dda_advance(dda: ptr<function, Dda>) -> bool {
    let tn = (*dda).t_next;
    let t = min(min(tn.x, tn.y), tn.z);
    if t >= (*dda).t_end {
        return false;
    }
    let x = tn.x == t;
    let y = !x && tn.y == t;
    let axis = vec3<bool>(x, y, !x && !y);
    (*dda).cell += select(vec3i(0), (*dda).step, axis);
    (*dda).t_next += select(vec3f(0.0), (*dda).t_delta, axis);
    let c = (*dda).cell;
    return all(c >= vec3i(0)) && all(c < (*dda).dims);
}
