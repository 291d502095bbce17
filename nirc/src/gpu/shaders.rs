//! Assembles the WGSL of each pass: generated constants (sizes, level tables, tile shapes), the
//! shared files of nirc/shaders/, then the pass itself.

use crate::config::NircConfig;
use crate::layout::ParameterLayout;
use crate::reliability::cell_count;

pub const WORKGROUP_SIZE: u32 = 64;

const COMMON: &str = include_str!("../../shaders/bindings_common.wgsl");
const FIXED_SUM: &str = include_str!("../../shaders/fixed_sum.wgsl");
const FIXED_SUM_READ: &str = include_str!("../../shaders/fixed_sum_read.wgsl");
const ENCODING: &str = include_str!("../../shaders/encoding.wgsl");
const MLP_LAYOUT: &str = include_str!("../../shaders/mlp_layout.wgsl");
const MLP: &str = include_str!("../../shaders/mlp.wgsl");
const MLP_TILE: &str = include_str!("../../shaders/mlp_tile.wgsl");
const ANSWER: &str = include_str!("../../shaders/answer.wgsl");
const WEIGHTS: &str = include_str!("../../shaders/weights.wgsl");
const LOSS: &str = include_str!("../../shaders/loss.wgsl");
const TRAIN_BINDINGS: &str = include_str!("../../shaders/train_bindings.wgsl");
const INFER_BINDINGS: &str = include_str!("../../shaders/infer_bindings.wgsl");
const RELIABILITY: &str = include_str!("../../shaders/reliability.wgsl");
pub const TRAIN_FORWARD_BACKWARD: &str = include_str!("../../shaders/train_forward_backward.wgsl");
pub const WEIGHT_GRADIENT: &str = include_str!("../../shaders/weight_gradient.wgsl");
pub const ADAM_EMA: &str = include_str!("../../shaders/adam_ema.wgsl");
pub const RELIABILITY_ACCUMULATE: &str = include_str!("../../shaders/reliability_accumulate.wgsl");
pub const RELIABILITY_UPDATE: &str = include_str!("../../shaders/reliability_update.wgsl");
pub const RELIABILITY_WALK: &str = include_str!("../../shaders/reliability_walk.wgsl");
pub const FINISH_STEP: &str = include_str!("../../shaders/finish_step.wgsl");
pub const INFER: &str = include_str!("../../shaders/infer.wgsl");
pub const TRAIN_TILE: &str = include_str!("../../shaders/train_tile.wgsl");
pub const INFER_TILE: &str = include_str!("../../shaders/infer_tile.wgsl");

/// Records per partial sum of the weight gradient (`cpu::cache::GRADIENT_CHUNK`): one training
/// tile.
pub const CHUNK: u32 = crate::cpu::cache::GRADIENT_CHUNK as u32;

/// Records per workgroup of the tiled training pass, queries per workgroup of the tiled
/// inference (smaller, so that the second predictor's inputs fit beside the tiles).
pub const TRAIN_TILE_RECORDS: u32 = 64;
pub const INFER_TILE_QUERIES: u32 = 32;
const _: () = assert!(TRAIN_TILE_RECORDS == CHUNK);

/// How the MLP passes are written.
#[derive(Clone, Copy, Debug, PartialEq, Eq, serde::Serialize)]
pub enum WeightPlacement {
    /// Tiled matrix products in workgroup memory (mlp_tile.wgsl): widths 32 and 64, at most 64
    /// inputs.
    Tiled,
    /// One invocation per record, weights read from the storage buffer (any network).
    Storage,
}

/// Invocation (rq, oq) of a tile computes 4 records x OPT outputs: RQ = tile / 4 record quads,
/// 64 / RQ output blocks.
struct TileShape {
    tile: u32,
    rq: u32,
    opt: u32,
}

fn tile_shape(layout: &ParameterLayout, tile: u32) -> TileShape {
    let rq = tile / 4;
    TileShape { tile, rq, opt: layout.width / (WORKGROUP_SIZE / rq) }
}

fn block_stride(n: u32, opt: u32) -> u32 {
    n.div_ceil(opt) * (opt / 4)
}

/// vec4s of tile_w a pass needs: the largest W^T, W, or (training) activation tile.
fn tile_w_vec4(layout: &ParameterLayout, shape: &TileShape, training: bool) -> u32 {
    let mut need = 0;
    for m in &layout.matrices {
        need = need.max(block_stride(m.rows, shape.opt) * m.cols);
        if training {
            need = need.max(block_stride(m.cols, shape.opt) * m.rows).max(shape.tile * block_stride(m.cols, shape.opt));
        }
    }
    need
}

/// Why the tiled passes cannot run this network, if they cannot.
pub fn tiled_unsupported(layout: &ParameterLayout) -> Option<String> {
    if !(layout.width == 32 || layout.width == 64) {
        return Some(format!("width {} (the tiled MLP takes 32 or 64)", layout.width));
    }
    if layout.input_dims > 64 {
        return Some(format!("{} network inputs (the tiled MLP takes at most 64)", layout.input_dims));
    }
    None
}

/// The structs declared once for Rust and WGSL (`render::gpu_struct!`) that the passes use.
pub fn structs() -> String {
    use render::gpu_struct::GpuStruct;
    [super::Hyper::WGSL.to_string(), super::Call::WGSL.to_string(), crate::records::wgsl(), crate::cpu::optimizer::Counters::WGSL.to_string(), crate::cpu::optimizer::counters_atomic_wgsl()].concat()
}

fn prelude(config: &NircConfig, layout: &ParameterLayout) -> String {
    let (dir_kind, dir_bands) = config.direction.code();
    let mut s = structs();
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
    c("DIR_DIMS", layout.direction_dims);
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

fn tile_constants(layout: &ParameterLayout, shape: &TileShape, training: bool) -> String {
    let mut s = String::new();
    for (name, v) in [
        ("TILE", shape.tile),
        ("RQ", shape.rq),
        ("OPT", shape.opt),
        ("TILE_A_VEC4", 64 * shape.rq),
        ("TILE_W_VEC4", tile_w_vec4(layout, shape, training)),
        ("STASH_VEC4", layout.input_dims * shape.rq),
    ] {
        s.push_str(&format!("const {name}: u32 = {v}u;\n"));
    }
    s.push_str(&tile_matmul(shape.opt));
    s
}

/// The tiled matrix product of mlp_tile.wgsl, unrolled over the OPT outputs of a block.
fn tile_matmul(opt: u32) -> String {
    let mut s = String::from("fn tile_matmul(reduce_len: u32, stride: u32, o0: u32, rq: u32) -> Block {\n");
    for j in 0..opt {
        s.push_str(&format!("    var acc{j} = vec4<f32>(0.0);\n"));
    }
    s.push_str("    let wb = o0 / 4u;\n    for (var k = 0u; k < reduce_len; k++) {\n        let a = tile_a[k * RQ + rq];\n        let row = k * stride + wb;\n");
    for q in 0..opt / 4 {
        s.push_str(&format!("        let w{q} = tile_w[row + {q}u];\n"));
        for (c, comp) in ["x", "y", "z", "w"].iter().enumerate() {
            s.push_str(&format!("        acc{j} += a * w{q}.{comp};\n", j = 4 * q + c as u32));
        }
    }
    let accs: Vec<String> = (0..opt).map(|j| format!("acc{j}")).collect();
    s.push_str(&format!("    }}\n    return Block({});\n}}\n", accs.join(", ")));
    s
}

/// Bytes of workgroup memory the tiled training and inference passes declare (the larger).
pub fn workgroup_bytes(layout: &ParameterLayout) -> u32 {
    let train = tile_shape(layout, TRAIN_TILE_RECORDS);
    let infer = tile_shape(layout, INFER_TILE_QUERIES);
    let train_bytes = (64 * train.rq + tile_w_vec4(layout, &train, true)) * 16;
    let infer_bytes = (64 * infer.rq + tile_w_vec4(layout, &infer, false) + layout.input_dims * infer.rq) * 16;
    train_bytes.max(infer_bytes)
}

/// The full source of one pass.
pub fn source(config: &NircConfig, layout: &ParameterLayout, pass: &str) -> String {
    let mut s = prelude(config, layout);
    let parts: Vec<&str> = match pass {
        "train_tile" => {
            s.push_str(&tile_constants(layout, &tile_shape(layout, TRAIN_TILE_RECORDS), true));
            vec![COMMON, TRAIN_BINDINGS, WEIGHTS, MLP_LAYOUT, MLP_TILE, ENCODING, FIXED_SUM, LOSS, TRAIN_TILE]
        }
        "infer_tile" => {
            s.push_str(&tile_constants(layout, &tile_shape(layout, INFER_TILE_QUERIES), false));
            vec![COMMON, INFER_BINDINGS, WEIGHTS, MLP_LAYOUT, MLP_TILE, ENCODING, RELIABILITY, ANSWER, INFER_TILE]
        }
        "train_forward_backward" => vec![COMMON, TRAIN_BINDINGS, WEIGHTS, MLP_LAYOUT, MLP, ENCODING, FIXED_SUM, LOSS, TRAIN_FORWARD_BACKWARD],
        "weight_gradient" => vec![COMMON, MLP_LAYOUT, WEIGHT_GRADIENT],
        "adam_ema" => vec![COMMON, FIXED_SUM_READ, ADAM_EMA],
        "reliability_accumulate" => vec![COMMON, RELIABILITY, FIXED_SUM, RELIABILITY_ACCUMULATE],
        "reliability_update" => vec![COMMON, RELIABILITY, FIXED_SUM_READ, RELIABILITY_UPDATE],
        "reliability_walk" => vec![COMMON, RELIABILITY, RELIABILITY_WALK],
        "finish_step" => vec![COMMON, FINISH_STEP],
        "infer" => vec![COMMON, INFER_BINDINGS, WEIGHTS, MLP_LAYOUT, MLP, ENCODING, RELIABILITY, ANSWER, INFER],
        other => panic!("unknown NIRC pass '{other}'"),
    };
    for p in parts {
        s.push('\n');
        s.push_str(p);
    }
    s
}

/// Every WGSL file of the cache's passes, concatenated (part of warm-start keys).
pub fn all_sources() -> String {
    [
        &structs(),
        COMMON, TRAIN_BINDINGS, INFER_BINDINGS, WEIGHTS, LOSS, FIXED_SUM, FIXED_SUM_READ, ENCODING, MLP_LAYOUT, MLP, MLP_TILE, ANSWER, RELIABILITY, TRAIN_FORWARD_BACKWARD, TRAIN_TILE, WEIGHT_GRADIENT, ADAM_EMA, RELIABILITY_ACCUMULATE,
        RELIABILITY_UPDATE, RELIABILITY_WALK, FINISH_STEP, INFER, INFER_TILE,
    ]
    .join("\n")
}
