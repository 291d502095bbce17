// Shapes and offsets of the MLP matrices and of the per-record training scratch
// (CPU mirror: src/layout.rs).

import package::nirc::config::{HIDDEN, IN_DIMS, IN_STRIDE, WIDTH};

fn mat_rows(k: u32) -> u32 {
    return select(WIDTH, 3u, k == HIDDEN);
}
fn mat_cols(k: u32) -> u32 {
    return select(WIDTH, IN_DIMS, k == 0u);
}
fn mat_offset(k: u32) -> u32 {
    return select(WIDTH * IN_DIMS + (k - 1u) * WIDTH * WIDTH, 0u, k == 0u);
}
// Where the input of matrix k starts in `acts` (the network input, then hidden layer outputs).
fn act_base(k: u32) -> u32 {
    return select(IN_STRIDE + (k - 1u) * WIDTH, 0u, k == 0u);
}
// Where the gradient of matrix k's pre-activation output starts in `deltas`.
fn delta_base(k: u32) -> u32 {
    return k * WIDTH;
}
