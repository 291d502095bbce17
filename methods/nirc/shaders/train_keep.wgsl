// What the tiled training keeps for the backward pass (mlp_tile.wgsl's `keep_activation` hook):
// the High-LR predictor's activations and pre-activation gradients in each record's `scratch`
// slot, a quad at a time (the offsets, o0 and the counts kept are multiples of 4 in the networks
// the tiles take). `tile_first` is the tile's first record (set by train_tile.wgsl).

import package::nirc::config::{SCRATCH_STRIDE, WIDTH};
import package::nirc::bindings::{call, scratch};
import package::nirc::tile::{Block, OPT};
import package::nirc::mlp_layout::{act_base};

var<private> tile_first: u32;

// Scratch offset of value `v` of record 4 rq + c of this tile; records past the batch have none.
fn record_slot(rq: u32, c: u32) -> u32 {
    return (tile_first + 4u * rq + c) * SCRATCH_STRIDE;
}
fn record_valid(rq: u32, c: u32) -> bool {
    return tile_first + 4u * rq + c < call.n;
}

// Saves this invocation's block (records 4 rq .., values o0 .. below `count`) at `offset` in each
// valid record's scratch slot.
fn keep_block(offset: u32, rq: u32, o0: u32, block: Block, count: u32) {
    for (var c = 0u; c < 4u; c++) {
        if record_valid(rq, c) {
            let b = (record_slot(rq, c) + offset + o0) / 4u;
            for (var j = 0u; j < OPT; j += 4u) {
                if o0 + j < count {
                    scratch[b + j / 4u] = vec4<f32>(block[j][c], block[j + 1u][c], block[j + 2u][c], block[j + 3u][c]);
                }
            }
        }
    }
}

// Saves the High-LR predictor's hidden activations (inputs of matrix `layer`).
fn keep_activation(layer: u32, rq: u32, o0: u32, block: Block) {
    keep_block(act_base(layer), rq, o0, block, WIDTH);
}
