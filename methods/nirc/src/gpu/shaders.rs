//! Assembles the WGSL of each pass: generated constants (sizes, level tables, tile shapes), the
//! shared files of methods/nirc/shaders/, then the pass itself.

use super::WORKGROUP_SIZE;
use crate::config::NircCacheSettings;
use crate::layout::ParameterLayout;
use crate::reliability::cell_count;
use render::shader::{Module, Program};

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
    /// Training as `Tiled` (so it takes the networks `Tiled` takes); inference with one query
    /// per invocation, its activations in registers and both predictors' weights in a uniform
    /// buffer (src/gpu/lane.rs, infer_lane.wgsl). The default on CPU adapters, where it is the
    /// faster form.
    Registers,
}

impl WeightPlacement {
    /// The form `FLICKER_NIRC_MLP` asks for (`tiled`, `registers` or `storage`), to compare forms
    /// in whole scenarios; unset or empty: the adapter's default.
    pub fn from_env() -> Result<Option<Self>, crate::NircError> {
        match std::env::var("FLICKER_NIRC_MLP").unwrap_or_default().as_str() {
            "" => Ok(None),
            "tiled" => Ok(Some(Self::Tiled)),
            "registers" => Ok(Some(Self::Registers)),
            "storage" => Ok(Some(Self::Storage)),
            other => Err(crate::NircError::Config(format!(
                "FLICKER_NIRC_MLP is '{other}'; expected tiled, registers or storage"
            ))),
        }
    }

    /// Whether training runs the tiled pass.
    pub fn tiled_training(self) -> bool {
        self != WeightPlacement::Storage
    }
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
            need = need
                .max(block_stride(m.cols, shape.opt) * m.rows)
                .max(shape.tile * block_stride(m.cols, shape.opt));
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
        return Some(format!(
            "{} network inputs (the tiled MLP takes at most 64)",
            layout.input_dims
        ));
    }
    None
}

/// The structs declared once for Rust and WGSL (`render::gpu_struct!`) that the passes use.
pub fn structs() -> String {
    use render::gpu_struct::GpuStruct;
    [
        super::Hyper::WGSL.to_string(),
        super::Call::WGSL.to_string(),
        crate::records::wgsl(),
        crate::cpu::optimizer::Counters::WGSL.to_string(),
        crate::cpu::optimizer::counters_atomic_wgsl(),
    ]
    .concat()
}

/// The network's sizes, level tables and grid constants (`package::nirc::config`).
fn config_constants(config: &NircCacheSettings, layout: &ParameterLayout) -> String {
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
    // The quads the dense Adam and EMA passes cover: all, or with sparse grid updates the MLP's
    // (adam_sparse.wgsl takes the grid).
    c(
        "DENSE_QUADS",
        if config.optimizer.sparse_grid { layout.mlp_params } else { layout.total_params } / 4,
    );
    c("MLP_WEIGHTS", layout.mlp_weights());
    c("TOTAL_PARAMS", layout.total_params);
    c("ACT_FLOATS", layout.activation_floats());
    c("DELTA_FLOATS", layout.delta_floats());
    c("IN_STRIDE", layout.input_stride());
    c("SCRATCH_STRIDE", layout.scratch_stride());
    c("CELL_COUNT", cell_count(&config.reliability));
    c("CHUNK", CHUNK);
    c("WG_SIZE", WORKGROUP_SIZE);
    c("DIR_DIMS", layout.direction_dims);
    let table = |name: &str, f: &dyn Fn(&crate::layout::GridLevel) -> u32| {
        let values: Vec<String> = layout.levels.iter().map(|l| format!("{}u", f(l))).collect();
        format!(
            "var<private> {name}: array<u32, LEVELS> = array<u32, LEVELS>({});\n",
            values.join(", ")
        )
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
    // The tiles of mlp_tile.wgsl, sized for this network.
    s.push_str("var<workgroup> tile_a: array<vec4<f32>, TILE_A_VEC4>;\nvar<workgroup> tile_w: array<vec4<f32>, TILE_W_VEC4>;\nalias Block = array<vec4<f32>, OPT>;\n");
    s.push_str(&tile_matmul(shape.opt));
    s
}

/// The tiled matrix product of mlp_tile.wgsl, unrolled over the OPT outputs of a block.
fn tile_matmul(opt: u32) -> String {
    let mut s =
        String::from("fn tile_matmul(reduce_len: u32, stride: u32, o0: u32, rq: u32) -> Block {\n");
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
    let infer_bytes =
        (64 * infer.rq + tile_w_vec4(layout, &infer, false) + layout.input_dims * infer.rq) * 16;
    train_bytes.max(infer_bytes)
}

/// A file of methods/nirc/shaders/ as a module.
macro_rules! nirc_file {
    ($name:literal) => {
        render::wgsl_file!($name)
    };
}

/// The program of one pass: generated structs (`package::nirc::types`) and constants
/// (`package::nirc::config`, and `package::nirc::tile` for the tiled passes), the pass's bindings
/// as `package::nirc::bindings` and, for the tiled passes, its activation hook as
/// `package::nirc::keep` (the shared files import both by those names), the shared files, and
/// the pass's entry-point file. `grid_width`: the grid mirror's texture width where the
/// passes read and write it (grid_textures.rs).
pub fn program(
    config: &NircCacheSettings,
    layout: &ParameterLayout,
    pass: &str,
    grid_width: Option<u32>,
) -> Program {
    let mut modules = vec![
        Module::generated("package::nirc::types", &[&structs()]),
        Module::generated("package::nirc::config", &[&config_constants(config, layout)]),
        Module::generated("package::nirc::grid", &[&super::grid_textures::read_module(grid_width)]),
        Module::generated(
            "package::nirc::grid_write",
            &[&super::grid_textures::write_module(grid_width)],
        ),
    ];
    if pass == "train_tile" || pass == "train_forward_backward" {
        modules.push(Module::generated(
            "package::nirc::sparse_mark",
            &[sparse_mark_module(config.optimizer.sparse_grid)],
        ));
    }
    let tile = match pass {
        "train_tile" => Some((TRAIN_TILE_RECORDS, true)),
        "infer_tile" => Some((INFER_TILE_QUERIES, false)),
        _ => None,
    };
    if let Some((records, training)) = tile {
        modules.push(Module::generated(
            "package::nirc::tile",
            &[&tile_constants(layout, &tile_shape(layout, records), training)],
        ));
    }
    if pass == "infer_lane" || pass == "lane_stage" {
        modules.push(Module::generated(
            "package::nirc::lane",
            &[&super::lane::module(layout, grid_width.is_some())],
        ));
    }
    if pass == "infer_lane" {
        modules.push(Module::generated(
            "package::nirc::lane_queries",
            &[&super::lane::queries_module()],
        ));
    }
    let (own, entry) = pass_files(pass);
    modules.extend(own);
    modules.extend(shared_files());
    Program::new(modules).entry(entry)
}

/// Binding of the training passes' bitmask of touched grid quads (sparse grid updates).
pub const SPARSE_MARK_BINDING: u32 = 14;

/// `mark_touched(index)` of the training passes: with sparse grid updates, it sets the bits of
/// the grid quads of a corner's FEATURES parameters (index: the first), which touched_list.wgsl
/// then lists in ascending order; without, nothing.
fn sparse_mark_module(sparse: bool) -> &'static str {
    if sparse {
        "import package::nirc::config::{FEATURES, MLP_PARAMS};\n\
         @group(0) @binding(14) var<storage, read_write> touched_bits: array<atomic<u32>>;\n\
         fn mark_quad(r: u32) {\n    let word = r / 32u;\n    let bit = 1u << (r % 32u);\n    \
         // A plain look first: most corners of the coarse levels are marked already.\n    \
         if (atomicLoad(&touched_bits[word]) & bit) == 0u {\n        \
         atomicOr(&touched_bits[word], bit);\n    }\n}\n\
         fn mark_touched(index: u32) {\n    \
         for (var r = (index - MLP_PARAMS) / 4u; r <= (index + FEATURES - 1u - MLP_PARAMS) / 4u; r++) {\n        \
         mark_quad(r);\n    }\n}\n"
    } else {
        "fn mark_touched(index: u32) {}\n"
    }
}

/// The passes, by name.
const PASSES: [&str; 14] = [
    "train_tile",
    "infer_tile",
    "infer_lane",
    "lane_stage",
    "train_forward_backward",
    "infer",
    "reliability_accumulate",
    "reliability_update",
    "reliability_walk",
    "weight_gradient",
    "adam_ema",
    "adam_sparse",
    "touched_list",
    "finish_step",
];

/// A pass's own files: its bindings (`package::nirc::bindings`), the tiled passes' activation hook
/// (`package::nirc::keep`), and its entry-point file.
fn pass_files(pass: &str) -> (Vec<Module>, Module) {
    let bindings = |m: Module| m.at("package::nirc::bindings");
    let keep = |m: Module| m.at("package::nirc::keep");
    match pass {
        "train_tile" => (
            vec![bindings(nirc_file!("train_bindings.wgsl")), keep(nirc_file!("train_keep.wgsl"))],
            nirc_file!("train_tile.wgsl"),
        ),
        "infer_tile" => (
            vec![bindings(nirc_file!("infer_bindings.wgsl")), keep(nirc_file!("keep_none.wgsl"))],
            nirc_file!("infer_tile.wgsl"),
        ),
        "infer_lane" => {
            (vec![bindings(nirc_file!("infer_bindings.wgsl"))], nirc_file!("infer_lane.wgsl"))
        }
        "lane_stage" => {
            (vec![bindings(nirc_file!("infer_bindings.wgsl"))], nirc_file!("lane_stage.wgsl"))
        }
        "train_forward_backward" => (
            vec![bindings(nirc_file!("train_bindings.wgsl"))],
            nirc_file!("train_forward_backward.wgsl"),
        ),
        "infer" => (vec![bindings(nirc_file!("infer_bindings.wgsl"))], nirc_file!("infer.wgsl")),
        "reliability_accumulate" => (
            vec![bindings(nirc_file!("reliability_accumulate_bindings.wgsl"))],
            nirc_file!("reliability_accumulate.wgsl"),
        ),
        "reliability_update" => (
            vec![bindings(nirc_file!("reliability_update_bindings.wgsl"))],
            nirc_file!("reliability_update.wgsl"),
        ),
        "reliability_walk" => (
            vec![bindings(nirc_file!("reliability_walk_bindings.wgsl"))],
            nirc_file!("reliability_walk.wgsl"),
        ),
        "weight_gradient" => (vec![], nirc_file!("weight_gradient.wgsl")),
        "adam_ema" => (vec![], nirc_file!("adam_ema.wgsl")),
        "adam_sparse" => (vec![], nirc_file!("adam_sparse.wgsl")),
        "touched_list" => (vec![], nirc_file!("touched_list.wgsl")),
        "finish_step" => (vec![], nirc_file!("finish_step.wgsl")),
        other => panic!("unknown NIRC pass '{other}'"),
    }
}

/// The files the passes share (each pass's program lists them all; a pass links what it imports).
fn shared_files() -> [Module; 12] {
    [
        nirc_file!("adam_step.wgsl"),
        nirc_file!("bindings_common.wgsl"),
        nirc_file!("weights.wgsl"),
        nirc_file!("mlp_layout.wgsl"),
        nirc_file!("mlp.wgsl"),
        nirc_file!("mlp_tile.wgsl"),
        nirc_file!("encoding.wgsl"),
        nirc_file!("fixed_sum.wgsl"),
        nirc_file!("fixed_sum_read.wgsl"),
        nirc_file!("loss.wgsl"),
        nirc_file!("reliability.wgsl"),
        nirc_file!("answer.wgsl"),
    ]
}

/// Every WGSL file of the cache's passes, each once, and its generated structs (part of
/// warm-start keys; the generated constants follow from the key's configuration).
pub fn all_sources() -> String {
    let mut files: Vec<Module> = vec![Module::generated("package::nirc::types", &[&structs()])];
    files.extend(shared_files());
    for pass in PASSES {
        let (own, entry) = pass_files(pass);
        for m in own.into_iter().chain([entry]) {
            if !files.iter().any(|f| f.file == m.file) {
                files.push(m);
            }
        }
    }
    Program::new(files).fingerprint()
}
