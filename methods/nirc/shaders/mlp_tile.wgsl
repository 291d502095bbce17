// The tiny MLP as tiled matrix products in workgroup memory (CPU mirror: src/cpu/mlp.rs).
// A workgroup of 64 invocations works on TILE records. `tile_a` holds the operand that is read
// per record: reduction row k, record quad q at tile_a[k * RQ + q] (4 records in one vec4).
// `tile_w` holds the other operand, reduction row k at tile_w[k * stride ..]. Invocation
// (rq = lid % RQ, oq = lid / RQ) computes 4 records x OPT outputs, so each vec4 read from
// tile_a feeds 4 * OPT multiply-adds and no per-invocation array is indexed at run time
// (lavapipe turns that into scattered memory traffic). Every sum runs over k in order, as the
// CPU reference does. The tiles, `Block` and `tile_matmul` are generated per network
// (package::nirc::tile, src/gpu/shaders.rs); `keep_activation` is the pass's hook
// (train_keep.wgsl or keep_none.wgsl as package::nirc::keep).

import package::nirc::config::{HIDDEN, WG_SIZE};
import package::nirc::tile::{Block, OPT, RQ, tile_a, tile_matmul, tile_w};
import package::nirc::weights::{weight};
import package::nirc::mlp_layout::{mat_cols, mat_offset, mat_rows};
import package::nirc::keep::{keep_activation};

// vec4s per row of tile_w when n outputs are split into blocks of OPT (zero padded, so an
// invocation whose block starts inside the row never reads past it).
fn block_stride(n: u32) -> u32 {
    return (n + OPT - 1u) / OPT * (OPT / 4u);
}

// Matrix m of predictor `net` into tile_w, zero padded: transposed for the forward pass
// (tile_w[k * stride + i / 4][i % 4] = W[i][k]), as it is for the backward pass
// (tile_w[i * stride + j / 4][j % 4] = W[i][j]).
fn load_matrix(net: u32, m: u32, lid: u32, transposed: bool) {
    let rows = mat_rows(m);
    let cols = mat_cols(m);
    let outputs = select(cols, rows, transposed);
    let row = block_stride(outputs) * 4u;
    // A quad of tile_w per step, stored whole (one workgroup store where four would each be a
    // loop over the SIMD lanes on lavapipe); row is a multiple of 4, so a quad never spans rows.
    for (var e4 = lid; e4 < row / 4u * select(rows, cols, transposed); e4 += WG_SIZE) {
        let k = (4u * e4) / row;
        let o0 = (4u * e4) % row;
        var v = vec4<f32>(0.0);
        for (var c = 0u; c < 4u; c++) {
            let o = o0 + c;
            if o < outputs {
                let i = select(k, o, transposed);
                let j = select(o, k, transposed);
                v[c] = weight(net, mat_offset(m) + i * cols + j);
            }
        }
        tile_w[e4] = v;
    }
}

// tile_matmul(reduce_len, stride, o0, rq) -> Block: out[o0 + j][record 4 rq + c] = sum over
// k < reduce_len of tile_a[k][4 rq + c] * tile_w[k][o0 + j], k in order. Generated for the
// pass's OPT (src/gpu/shaders.rs) with one named accumulator per output: an accumulator array
// indexed in a loop would live in memory on lavapipe.

// Writes a block into rows o0.. of tile_a (rows below `rows` only). Call after a barrier.
fn store_block(block: Block, rows: u32, o0: u32, rq: u32) {
    for (var j = 0u; j < OPT; j++) {
        if o0 + j < rows {
            tile_a[(o0 + j) * RQ + rq] = block[j];
        }
    }
}

// ReLU with the CPU's rule: anything not > 0 (NaN included) becomes 0.
fn relu4(v: vec4<f32>) -> vec4<f32> {
    return select(vec4<f32>(0.0), v, v > vec4<f32>(0.0));
}

// Forward of predictor `net` from the inputs in tile_a rows 0..IN_DIMS. Each hidden layer's
// output replaces tile_a (after a barrier); with `keep`, keep_activation sees it first. Returns
// this invocation's output block: outputs 0..3 are valid where oq == 0. Call from uniform
// control flow.
fn mlp_forward_tile(net: u32, lid: u32, keep: bool) -> Block {
    let rq = lid % RQ;
    let o0 = (lid / RQ) * OPT;
    var acc: Block;
    for (var m = 0u; m <= HIDDEN; m++) {
        workgroupBarrier();
        load_matrix(net, m, lid, true);
        workgroupBarrier();
        let rows = mat_rows(m);
        acc = Block();
        if o0 < rows {
            acc = tile_matmul(mat_cols(m), block_stride(rows), o0, rq);
        }
        if m < HIDDEN {
            for (var j = 0u; j < OPT; j++) {
                acc[j] = relu4(acc[j]);
            }
            if keep && o0 < rows {
                keep_activation(m + 1u, rq, o0, acc);
            }
            workgroupBarrier();
            store_block(acc, rows, o0, rq);
        }
    }
    return acc;
}
