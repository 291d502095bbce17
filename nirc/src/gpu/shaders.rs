//! Assembles the WGSL of each pass: generated constants (sizes, level tables), the shared files
//! of nirc/shaders/, the weight-access chunk (workgroup copy or storage), then the pass itself.

use crate::config::NircConfig;
use crate::layout::ParameterLayout;
use crate::reliability::cell_count;

pub const WORKGROUP_SIZE: u32 = 64;

const COMMON: &str = include_str!("../../shaders/bindings_common.wgsl");
const COUNTERS: &str = include_str!("../../shaders/counters.wgsl");
const FIXED_SUM: &str = include_str!("../../shaders/fixed_sum.wgsl");
const FIXED_SUM_READ: &str = include_str!("../../shaders/fixed_sum_read.wgsl");
const ENCODING: &str = include_str!("../../shaders/encoding.wgsl");
const MLP_LAYOUT: &str = include_str!("../../shaders/mlp_layout.wgsl");
const MLP: &str = include_str!("../../shaders/mlp.wgsl");
const RELIABILITY: &str = include_str!("../../shaders/reliability.wgsl");
pub const TRAIN_FORWARD_BACKWARD: &str = include_str!("../../shaders/train_forward_backward.wgsl");
pub const WEIGHT_GRADIENT: &str = include_str!("../../shaders/weight_gradient.wgsl");
pub const ADAM_EMA: &str = include_str!("../../shaders/adam_ema.wgsl");
pub const RELIABILITY_ACCUMULATE: &str = include_str!("../../shaders/reliability_accumulate.wgsl");
pub const RELIABILITY_UPDATE: &str = include_str!("../../shaders/reliability_update.wgsl");
pub const FINISH_STEP: &str = include_str!("../../shaders/finish_step.wgsl");
pub const INFER: &str = include_str!("../../shaders/infer.wgsl");

/// Records per partial sum of the weight gradient (`cpu::cache::GRADIENT_CHUNK`).
pub const CHUNK: u32 = crate::cpu::cache::GRADIENT_CHUNK as u32;

/// Where the forward/backward passes read the MLP weights from.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum WeightPlacement {
    /// Each workgroup copies one predictor's weights into workgroup memory (fits in budget).
    Workgroup,
    /// Straight from the storage buffer (weights larger than the workgroup memory budget).
    Storage,
}

fn prelude(config: &NircConfig, layout: &ParameterLayout) -> String {
    let (dir_kind, dir_bands) = config.direction.code();
    let mut s = String::new();
    let mut c = |name: &str, v: u32| s.push_str(&format!("const {name}: u32 = {v}u;\n"));
    c("IN_DIMS", layout.input_dims);
    c("WIDTH", layout.width);
    c("HIDDEN", layout.hidden_layers);
    c("LEVELS", layout.levels.len() as u32);
    c("FEATURES", layout.features_per_level);
    c("DIR_KIND", dir_kind);
    c("DIR_BANDS", dir_bands);
    c("MLP_PARAMS", layout.mlp_params);
    c("TOTAL_PARAMS", layout.total_params);
    c("ACT_FLOATS", layout.activation_floats());
    c("DELTA_FLOATS", layout.delta_floats());
    c("SCRATCH_STRIDE", layout.activation_floats() + layout.delta_floats());
    c("CELL_COUNT", cell_count(&config.reliability));
    c("CHUNK", CHUNK);
    c("WG_SIZE", WORKGROUP_SIZE);
    let table = |name: &str, f: &dyn Fn(&crate::layout::GridLevel) -> u32| {
        let values: Vec<String> = layout.levels.iter().map(|l| format!("{}u", f(l))).collect();
        format!("var<private> {name}: array<u32, LEVELS> = array<u32, LEVELS>({});\n", values.join(", "))
    };
    s.push_str(&table("level_resolution", &|l| l.resolution));
    s.push_str(&table("level_table_size", &|l| l.table_size));
    s.push_str(&table("level_offset", &|l| l.offset));
    s.push_str(&table("level_dense", &|l| l.dense as u32));
    s
}

fn weights_chunk(placement: WeightPlacement) -> &'static str {
    match placement {
        WeightPlacement::Workgroup => {
            "fn table(net: u32, i: u32) -> f32 { if net == 0u { return params[i]; } return ema[i]; }
var<workgroup> wg_weights: array<f32, MLP_PARAMS>;
fn weight(net: u32, i: u32) -> f32 { return wg_weights[i]; }
// Copies predictor `net`'s MLP weights into workgroup memory (barriers on both sides: the
// previous predictor may still be in use). Call from uniform control flow.
fn load_weights(net: u32, lid: u32) {
    workgroupBarrier();
    for (var i = lid; i < MLP_PARAMS; i += WG_SIZE) { wg_weights[i] = table(net, i); }
    workgroupBarrier();
}
"
        }
        WeightPlacement::Storage => {
            "fn table(net: u32, i: u32) -> f32 { if net == 0u { return params[i]; } return ema[i]; }
fn weight(net: u32, i: u32) -> f32 { return table(net, i); }
fn load_weights(net: u32, lid: u32) {}
"
        }
    }
}

/// Bytes of workgroup memory the forward passes declare with this placement.
pub fn workgroup_bytes(layout: &ParameterLayout, placement: WeightPlacement) -> u32 {
    match placement {
        WeightPlacement::Workgroup => layout.mlp_params * 4,
        WeightPlacement::Storage => 0,
    }
}

/// The full source of one pass.
pub fn source(config: &NircConfig, layout: &ParameterLayout, placement: WeightPlacement, pass: &str) -> String {
    let parts: Vec<&str> = match pass {
        "train_forward_backward" => vec![COMMON, COUNTERS, MLP_LAYOUT, MLP, ENCODING, FIXED_SUM, weights_chunk(placement), TRAIN_FORWARD_BACKWARD],
        "weight_gradient" => vec![COMMON, MLP_LAYOUT, WEIGHT_GRADIENT],
        "adam_ema" => vec![COMMON, COUNTERS, FIXED_SUM_READ, ADAM_EMA],
        "reliability_accumulate" => vec![COMMON, COUNTERS, RELIABILITY, FIXED_SUM, RELIABILITY_ACCUMULATE],
        "reliability_update" => vec![COMMON, COUNTERS, RELIABILITY, FIXED_SUM_READ, RELIABILITY_UPDATE],
        "finish_step" => vec![COMMON, COUNTERS, FINISH_STEP],
        "infer" => vec![COMMON, COUNTERS, MLP_LAYOUT, MLP, ENCODING, RELIABILITY, weights_chunk(placement), INFER],
        other => panic!("unknown NIRC pass '{other}'"),
    };
    let mut s = prelude(config, layout);
    for p in parts {
        s.push('\n');
        s.push_str(p);
    }
    s
}

/// Every WGSL file of the cache's passes, concatenated (part of warm-start keys).
pub fn all_sources() -> String {
    [COMMON, COUNTERS, FIXED_SUM, FIXED_SUM_READ, ENCODING, MLP_LAYOUT, MLP, RELIABILITY, TRAIN_FORWARD_BACKWARD, WEIGHT_GRADIENT, ADAM_EMA, RELIABILITY_ACCUMULATE, RELIABILITY_UPDATE, FINISH_STEP, INFER].join("\n")
}
