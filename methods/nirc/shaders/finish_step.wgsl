// Last pass of a training step or grid update (one thread): commits the counters, or counts a
// rolled-back step, and lowers the flag. call.mode: 0 = training step, 1 = grid update only.

import package::nirc::types::{Call, Counters, Hyper};

@group(0) @binding(0) var<storage, read> call: Call;
@group(0) @binding(1) var<storage, read> hyper: Hyper;
@group(0) @binding(2) var<storage, read_write> counters: Counters;

@compute @workgroup_size(1)
fn main() {
    if counters.flag == 0u {
        if call.mode == 0u {
            counters.step += 1u;
            counters.beta1_pow = counters.beta1_pow * hyper.beta1;
            counters.beta2_pow = counters.beta2_pow * hyper.beta2;
            counters.alpha_pow = counters.alpha_pow * hyper.alpha;
        }
        counters.grid_updates += 1u;
    } else {
        counters.rejected_steps += 1u;
    }
    counters.flag = 0u;
}
