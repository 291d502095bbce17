// Parameters of predictor `net` (0 = High-LR, 1 = EMA): hash-grid table entries and MLP weights
// live in one flat vector each (src/layout.rs). Reads the pass's `params` and `ema`
// (package::nirc::bindings).

import package::nirc::bindings::{ema, params};

fn table(net: u32, i: u32) -> f32 {
    if net == 0u {
        return params[i];
    }
    return ema[i];
}

fn weight(net: u32, i: u32) -> f32 {
    return table(net, i);
}
