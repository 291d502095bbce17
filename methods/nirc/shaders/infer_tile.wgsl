// Inference, tiled (mlp_tile.wgsl): one workgroup per TILE queries. The hash-grid corners of a
// query are found once and both predictors' tables are read from them; the first predictor the
// mode needs runs from tile_a while the other's inputs wait in `stash`. Then answer.wgsl.

import package::nirc::config::{DIR_DIMS, FEATURES, LEVELS, WG_SIZE};
import package::nirc::bindings::{call, hyper, queries};
import package::nirc::tile::{RQ, STASH_VEC4, TILE, tile_a};
import package::nirc::bindings_common::{normalize_to_bounds};
import package::nirc::encoding::{corner_sum, direction_feature, level_corners};
import package::nirc::answer::{predictors, write_answer, write_predictions};
import package::nirc::mlp_tile::{mlp_forward_tile};

var<workgroup> stash: array<vec4<f32>, STASH_VEC4>;

// Input row `row` of query t: into tile_a for the first predictor, into the stash for the second.
fn put_input(row: u32, t: u32, first: f32, second: f32, both: bool) {
    tile_a[row * RQ + t / 4u][t % 4u] = first;
    if both {
        stash[row * RQ + t / 4u][t % 4u] = second;
    }
}

@compute @workgroup_size(64)
fn main(@builtin(workgroup_id) wid: vec3<u32>, @builtin(local_invocation_index) lid: u32) {
    let base = wid.x * TILE;
    let mode = call.mode;
    if mode == 4u {
        let qi = base + lid;
        if lid < TILE && qi < call.n {
            write_answer(qi, queries[qi].position.xyz, mode, vec3<f32>(0.0), vec3<f32>(0.0));
        }
        return;
    }
    let pr = predictors(mode);
    let both = pr.both;
    let first_net = pr.first_net;

    // Encoding: invocation lid takes query lid % TILE and one half of the levels.
    let t = lid % TILE;
    let half = lid / TILE;
    let q = queries[min(base + t, call.n - 1u)];
    let p = normalize_to_bounds(hyper, q.position.xyz);
    let per_half = (LEVELS + 1u) / 2u;
    for (var l = half * per_half; l < min(LEVELS, (half + 1u) * per_half); l++) {
        let corners = level_corners(l, p);
        for (var k = 0u; k < FEATURES; k++) {
            let first = corner_sum(first_net, corners, k);
            var second = 0.0;
            if both {
                second = corner_sum(0u, corners, k);
            }
            put_input(l * FEATURES + k, t, first, second, both);
        }
    }
    if half == 0u {
        for (var i = 0u; i < DIR_DIMS; i++) {
            let d = direction_feature(q.direction.xyz, i);
            put_input(LEVELS * FEATURES + i, t, d, d, both);
        }
    }

    let a = mlp_forward_tile(first_net, lid, false);
    var f_first = array<vec4<f32>, 3>(a[0], a[1], a[2]);
    var f_second = array<vec4<f32>, 3>(vec4<f32>(0.0), vec4<f32>(0.0), vec4<f32>(0.0));
    if both {
        workgroupBarrier();
        for (var e = lid; e < STASH_VEC4; e += WG_SIZE) {
            tile_a[e] = stash[e];
        }
        let b = mlp_forward_tile(0u, lid, false);
        f_second = array<vec4<f32>, 3>(b[0], b[1], b[2]);
    }

    // The invocations holding output block 0 answer their 4 queries.
    let rq = lid % RQ;
    if lid / RQ == 0u {
        for (var c = 0u; c < 4u; c++) {
            let qi = base + 4u * rq + c;
            if qi < call.n {
                let f1 = vec3<f32>(f_first[0][c], f_first[1][c], f_first[2][c]);
                let f2 = vec3<f32>(f_second[0][c], f_second[1][c], f_second[2][c]);
                write_predictions(qi, queries[qi].position.xyz, mode, pr, f1, f2);
            }
        }
    }
}
