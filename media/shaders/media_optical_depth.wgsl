// The paper's Alg. 2 (prepare) and Alg. 1 (estimate), the twin of media::optical_depth:
// `count` i.i.d. optical depths of N samples each into od_x, with floor(I_j) + 1 + rand()
// (erratum of Alg. 1's ceil(I_j) + rand()).

import package::media::types::{RaySegment};
import package::media::media_rng::{media_rand};
import package::media::media_grid::{media_dims, BIG, super_voxel_size, importance, mu_at, super_voxel};
import package::media::media_dda::{dda_advance, dda_exit, dda_new};

const MAX_ESTIMATES: u32 = 9u;

// x: F, y: t'_min, z: t'_max.
fn od_prepare(s: RaySegment, variance_aware: bool) -> vec3f {
    var dda = dda_new(s, media_dims(), f32(super_voxel_size()));
    var out = vec3f(0.0, s.t1, s.t0);
    var t = s.t0;
    let bound = media_dims().x + media_dims().y + media_dims().z + 1u;
    for (var i = 0u; i < bound; i++) {
        let p = importance(super_voxel(dda.cell), variance_aware).x;
        let exit = dda_exit(dda);
        out.x += (exit - t) * p;
        if p != 0.0 {
            out.y = min(out.y, t);
            out.z = max(out.z, exit);
        }
        t = exit;
        if !dda_advance(&dda) {
            break;
        }
    }
    return out;
}

var<private> od_x: array<f32, 9>;

fn od_arg_min(i_next: ptr<function, array<f32, 9>>) -> u32 {
    var j = 0u;
    for (var k = 1u; k < MAX_ESTIMATES; k++) {
        if (*i_next)[k] < (*i_next)[j] {
            j = k;
        }
    }
    return j;
}

fn od_estimate(s: RaySegment, prep: vec3f, count: u32, samples: u32, variance_aware: bool, stratified: bool, rng: ptr<function, u32>) {
    var i_next: array<f32, 9>;
    for (var k = 0u; k < MAX_ESTIMATES; k++) {
        od_x[k] = 0.0;
        i_next[k] = BIG;
    }
    for (var k = 0u; k < count; k++) {
        i_next[k] = media_rand(rng);
    }
    if prep.x <= 0.0 {
        return;
    }
    let f_delta = prep.x / f32(samples);
    let tight = RaySegment(s.origin, prep.y, s.dir, prep.z);
    var dda = dda_new(tight, media_dims(), f32(super_voxel_size()));
    var imp = importance(super_voxel(dda.cell), variance_aware);
    var t_exit = dda_exit(dda);
    var f = (t_exit - tight.t0) * imp.x;
    var tau_c = (t_exit - tight.t0) * imp.y;
    var exhausted = false;
    var j = od_arg_min(&i_next);
    let dims = media_dims();
    let bound = count * samples + dims.x + dims.y + dims.z + 2u;
    for (var n = 0u; n < bound; n++) {
        if f_delta * i_next[j] >= f && exhausted {
            break;
        }
        for (var c = 0u; c < bound && f_delta * i_next[j] >= f && !exhausted; c++) {
            if !dda_advance(&dda) {
                exhausted = true;
                break;
            }
            let t_enter = t_exit;
            t_exit = dda_exit(dda);
            imp = importance(super_voxel(dda.cell), variance_aware);
            f += (t_exit - t_enter) * imp.x;
            tau_c += (t_exit - t_enter) * imp.y;
        }
        if f_delta * i_next[j] < f {
            let t = t_exit - (f - f_delta * i_next[j]) / imp.x;
            od_x[j] += (mu_at(tight, t, dda.cell) - imp.y) / imp.x;
            if stratified {
                i_next[j] = floor(i_next[j]) + 1.0 + media_rand(rng);
            } else {
                i_next[j] += 1.0;
            }
            j = od_arg_min(&i_next);
        }
    }
    for (var k = 0u; k < count; k++) {
        od_x[k] = f_delta * od_x[k] + tau_c;
    }
}

// Kettunen et al.'s sample count (media::optical_depth::kettunen_sample_count).
fn kettunen_sample_count(x: f32, multiplier: f32) -> u32 {
    let n_cmf = ceil(pow((x + 0.015) * (x + 0.65) * (x + 60.3), 1.0 / 3.0));
    return max(u32(round(multiplier * n_cmf / (1.0 + 0.31945))), 1u);
}

// N tied to the importance along the ray (Fig. 8d; media::optical_depth::tied_sample_count):
// ceil(F / step) in [1, 64].
fn tied_sample_count(total: f32, step: f32) -> u32 {
    return max(u32(min(ceil(total / step), 64.0)), 1u);
}
