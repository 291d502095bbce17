// Training, tiled (mlp_tile.wgsl): one workgroup per TILE records does everything a step needs
// per record. Encoding of both predictors (the hash-grid corners found once), forward of the
// EMA and High-LR predictors, relative L2 loss, backward of the High-LR predictor, hash-grid
// gradients as exact fixed-point sums (order-independent), the reliability samples
// (y, f_cur, f_EMA), and this tile's partial sums of the MLP weight gradients, records summed
// in order; `reduce` (weight_gradient.wgsl) then sums the tiles in order. Activations and
// pre-activation gradients go through `scratch` (record-major, as the per-record pass).

import package::nirc::types::{ReliabilitySample};
import package::nirc::config::{level_resolution, ACT_FLOATS, DIR_DIMS, FEATURES, HIDDEN, IN_DIMS, IN_STRIDE, LEVELS, MLP_PARAMS, SCRATCH_STRIDE, WG_SIZE, WIDTH};
import package::nirc::bindings::{accum, call, counters, hyper, losses, records, samples, scratch, scratch_set};
import package::nirc::tile::{Block, OPT, RQ, TILE, tile_a, tile_matmul, tile_w};
import package::nirc::bindings_common::{is_finite, normalize_to_bounds};
import package::nirc::mlp_layout::{act_base, delta_base, mat_cols, mat_offset, mat_rows};
import package::nirc::fixed_sum::{fixed_add};
import package::nirc::sparse_mark::{mark_touched};
import package::nirc::loss::{relative_l2};
import package::nirc::encoding::{cell_at, corner_sum, direction_feature, level_corner, level_corners};
import package::nirc::grid::{GRID_PAIRS, corner_pair};
import package::nirc::keep::{keep_block, record_slot, record_valid, tile_first};
import package::nirc::mlp_tile::{block_stride, load_matrix, mlp_forward_tile, store_block};

@group(0) @binding(10) var<storage, read_write> partials: array<f32>;

// Gradient of the pre-activation of matrix m - 1 from that of matrix m's input: ReLU passes it
// where the activation (saved by this invocation in the forward pass) was positive. The
// activations are read a quad at a time (WIDTH and o0 are multiples of 4).
fn relu_backward(g: Block, m: u32, rq: u32, o0: u32) -> Block {
    var out = g;
    for (var c = 0u; c < 4u; c++) {
        let valid = record_valid(rq, c);
        let b = select(0u, record_slot(rq, c) + act_base(m) + o0, valid) / 4u;
        for (var j = 0u; j < OPT; j += 4u) {
            var keep = vec4<bool>(false);
            if valid && o0 + j < WIDTH {
                keep = scratch[b + j / 4u] > vec4<f32>(0.0);
            }
            out[j][c] = select(0.0, g[j][c], keep.x);
            out[j + 1u][c] = select(0.0, g[j + 1u][c], keep.y);
            out[j + 2u][c] = select(0.0, g[j + 2u][c], keep.z);
            out[j + 3u][c] = select(0.0, g[j + 3u][c], keep.w);
        }
    }
    return out;
}

@compute @workgroup_size(64)
fn main(@builtin(workgroup_id) wid: vec3<u32>, @builtin(local_invocation_index) lid: u32) {
    tile_first = wid.x * TILE;
    let r = tile_first + lid;
    let in_range = r < call.n;
    let rec = records[min(r, call.n - 1u)];
    let rq = lid % RQ;
    let o0 = (lid / RQ) * OPT;
    let p = normalize_to_bounds(hyper, rec.position.xyz);

    // 1. Inputs: the EMA predictor's into tile_a, the High-LR predictor's into the scratch.
    for (var l = 0u; l < LEVELS; l++) {
        let corners = level_corners(l, p);
        if GRID_PAIRS {
            // Both features of a corner in one texel of the grid mirror (src/gpu/grid_textures.rs).
            let e = corner_pair(1u, corners);
            let h = corner_pair(0u, corners);
            tile_a[(l * FEATURES) * RQ + lid / 4u][lid % 4u] = e.x;
            tile_a[(l * FEATURES + 1u) * RQ + lid / 4u][lid % 4u] = e.y;
            if in_range {
                scratch_set(r * SCRATCH_STRIDE + l * FEATURES, h.x);
                scratch_set(r * SCRATCH_STRIDE + l * FEATURES + 1u, h.y);
            }
        } else {
            for (var k = 0u; k < FEATURES; k++) {
                tile_a[(l * FEATURES + k) * RQ + lid / 4u][lid % 4u] = corner_sum(1u, corners, k);
                if in_range {
                    scratch_set(r * SCRATCH_STRIDE + l * FEATURES + k, corner_sum(0u, corners, k));
                }
            }
        }
    }
    for (var i = 0u; i < DIR_DIMS; i++) {
        let d = direction_feature(rec.direction.xyz, i);
        tile_a[(LEVELS * FEATURES + i) * RQ + lid / 4u][lid % 4u] = d;
        if in_range {
            scratch_set(r * SCRATCH_STRIDE + LEVELS * FEATURES + i, d);
        }
    }

    // 2. Both forwards; output block 0 (o0 == 0) holds f of records 4 rq .. 4 rq + 3.
    let fe = mlp_forward_tile(1u, lid, false);
    let f_ema = array<vec4<f32>, 3>(fe[0], fe[1], fe[2]);
    workgroupBarrier();
    // A quad at a time; the rows from IN_DIMS to IN_STRIDE are padding the matrices do not read.
    for (var i = 0u; i < IN_STRIDE; i += 4u) {
        var v = vec4<f32>(0.0);
        if in_range {
            v = scratch[(r * SCRATCH_STRIDE + i) / 4u];
        }
        tile_a[i * RQ + lid / 4u][lid % 4u] = v.x;
        tile_a[(i + 1u) * RQ + lid / 4u][lid % 4u] = v.y;
        tile_a[(i + 2u) * RQ + lid / 4u][lid % 4u] = v.z;
        tile_a[(i + 3u) * RQ + lid / 4u][lid % 4u] = v.w;
    }
    let fc = mlp_forward_tile(0u, lid, true);

    // 3. Relative L2 loss (denominators under stop-gradient) and dL/df.
    var ok = true;
    var d_out = array<vec4<f32>, 3>(vec4<f32>(0.0), vec4<f32>(0.0), vec4<f32>(0.0));
    if o0 == 0u {
        for (var c = 0u; c < 4u; c++) {
            if record_valid(rq, c) {
                let rr = tile_first + 4u * rq + c;
                let record = records[rr];
                let f = vec3<f32>(fc[0][c], fc[1][c], fc[2][c]);
                let y = record.target_rgb.xyz;
                let l2 = relative_l2(f, y);
                let loss = l2.w;
                for (var ch = 0u; ch < 3u; ch++) {
                    d_out[ch][c] = l2[ch];
                    scratch_set(rr * SCRATCH_STRIDE + ACT_FLOATS + delta_base(HIDDEN) + ch, l2[ch]);
                }
                losses[rr] = loss;
                ok = is_finite(loss) && ok;
                let fe3 = vec3<f32>(f_ema[0][c], f_ema[1][c], f_ema[2][c]);
                samples[rr] = ReliabilitySample(record.position, record.target_rgb, vec4<f32>(f, 0.0), vec4<f32>(fe3, 0.0));
            }
        }
    }

    // 4. Backward of the High-LR predictor, matrix by matrix from the output; tile_a holds the
    //    pre-activation gradient of the matrix being passed (k-major), then dL/d(input).
    workgroupBarrier();
    if o0 == 0u {
        for (var ch = 0u; ch < 3u; ch++) {
            tile_a[ch * RQ + rq] = d_out[ch];
        }
    }
    for (var mm = 0u; mm <= HIDDEN; mm++) {
        let m = HIDDEN - mm;
        workgroupBarrier();
        load_matrix(0u, m, lid, false);
        workgroupBarrier();
        let cols = mat_cols(m);
        var g = Block();
        if o0 < cols {
            g = tile_matmul(mat_rows(m), block_stride(cols), o0, rq);
            if m > 0u {
                g = relu_backward(g, m, rq, o0);
                keep_block(ACT_FLOATS + delta_base(m - 1u), rq, o0, g, cols);
            }
        }
        workgroupBarrier();
        store_block(g, cols, o0, rq);
    }
    workgroupBarrier();

    // 5a. Prefetch. On a CPU the scatter below is locked adds at random places in a table of
    //     megabytes, and a locked add waits for the loads before it, so each cache miss would
    //     cost a full memory latency; plain loads of the same words first let the misses
    //     overlap (about 5 ms of a 4096-record step on lavapipe, docs/lab/nirc-speed.md).
    var touched = 0u;
    if in_range {
        for (var l = 0u; l < LEVELS; l++) {
            let cell = cell_at(p, level_resolution[l]);
            for (var c = 0u; c < 8u; c++) {
                touched ^= atomicLoad(&accum[3u * (level_corner(l, cell, c).index - MLP_PARAMS)]);
            }
        }
    }
    // 5. Hash-grid gradients, per record, corner by corner (with sparse grid updates, each
    //    corner's quads are listed for adam_sparse.wgsl).
    if in_range {
        for (var l = 0u; l < LEVELS; l++) {
            let cell = cell_at(p, level_resolution[l]);
            // Indexed only in loops of FEATURES (a constant) iterations: unrolled, it stays in registers.
            var d = array<f32, FEATURES>();
            for (var k = 0u; k < FEATURES; k++) {
                d[k] = tile_a[(l * FEATURES + k) * RQ + lid / 4u][lid % 4u];
            }
            for (var c = 0u; c < 8u; c++) {
                let corner = level_corner(l, cell, c);
                mark_touched(corner.index);
                for (var k = 0u; k < FEATURES; k++) {
                    ok = fixed_add(3u * (corner.index + k - MLP_PARAMS), corner.weight * d[k]) && ok;
                }
            }
        }
    }
    // Atomic loads are not dropped as dead code; `touched` also feeds a test that never holds
    // (call.n >= 1 in this pass), so that its value is used.
    if !ok || (touched == 0xdeadbeefu && call.n == 0u) {
        atomicOr(&counters.flag, 1u);
    }

    // 6. This tile's weight-gradient partial sums: dW_m[i][j] = sum over its records of
    //    delta_m[r][i] a_m[r][j]. Deltas (k = record, quads of i) into tile_a, activations into
    //    tile_w; invocation (rq, oq) sums rows 4 rq .. 4 rq + 3, columns o0 .. o0 + OPT - 1.
    storageBarrier();
    for (var m = 0u; m <= HIDDEN; m++) {
        let rows = mat_rows(m);
        let cols = mat_cols(m);
        let s = block_stride(cols);
        workgroupBarrier();
        // A quad of values per load; the parts of a quad past `rows` or `cols` are zeroed.
        for (var e = lid; e < TILE * RQ; e += WG_SIZE) {
            let rl = e / RQ;
            let i = 4u * (e % RQ);
            var v = vec4<f32>(0.0);
            if i < rows && tile_first + rl < call.n {
                v = scratch[((tile_first + rl) * SCRATCH_STRIDE + ACT_FLOATS + delta_base(m) + i) / 4u];
            }
            tile_a[e] = select(vec4<f32>(0.0), v, vec4<u32>(i) + vec4<u32>(0u, 1u, 2u, 3u) < vec4<u32>(rows));
        }
        for (var e = lid; e < TILE * s; e += WG_SIZE) {
            let rl = e / s;
            let j = 4u * (e % s);
            var v = vec4<f32>(0.0);
            if j < cols && tile_first + rl < call.n {
                v = scratch[((tile_first + rl) * SCRATCH_STRIDE + act_base(m) + j) / 4u];
            }
            tile_w[e] = select(vec4<f32>(0.0), v, vec4<u32>(j) + vec4<u32>(0u, 1u, 2u, 3u) < vec4<u32>(cols));
        }
        workgroupBarrier();
        if 4u * rq < rows && o0 < cols {
            let acc = tile_matmul(TILE, s, o0, rq);
            let off = mat_offset(m);
            for (var c = 0u; c < 4u; c++) {
                let i = 4u * rq + c;
                if i < rows {
                    for (var j = 0u; j < OPT; j++) {
                        if o0 + j < cols {
                            partials[wid.x * MLP_PARAMS + off + i * cols + o0 + j] = acc[j][c];
                        }
                    }
                }
            }
        }
    }
}
