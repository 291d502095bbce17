// mlp_tile.wgsl's `keep_activation` hook for inference: nothing is kept.

import package::nirc::tile::{Block};

fn keep_activation(layer: u32, rq: u32, o0: u32, block: Block) {}
