//! The register form of inference (`WeightPlacement::Registers`): `LANE_QUERIES` (4) queries per
//! invocation, each staged weight loaded once for all of them (2x the queries/s of one per
//! invocation on a newer lavapipe machine; docs/lab/nirc-speed.md), their inputs and activations in named
//! registers, both predictors' MLP weights in one uniform buffer (`lane_stage.wgsl` copies them
//! there, transposed, before each inference; `infer_lane.wgsl`).
//! Why this shape, from `bench::nirc_throughput::register_layer_probe` on lavapipe (Mesa 22.3): a
//! storage or workgroup load whose address is not a constant becomes a loop over the SIMD lanes, a
//! private array indexed at run time a scatter/gather, while a uniform-buffer load at a dynamically
//! uniform address is one scalar load; and a workgroup barrier is compiled as a coroutine
//! suspension, which made LLVM's coroutine splitting run for many minutes on a fully unrolled
//! network, so this form has no barrier. Each layer loops over its output quads with the inputs
//! unrolled; every sum runs over the inputs in order, as on the CPU. On a GPU every invocation
//! reads the same weight at once, which uniform memory serves as a broadcast.

use crate::layout::ParameterLayout;

const XYZW: [&str; 4] = ["x", "y", "z", "w"];

/// Queries per invocation of the register-form inference: each staged weight is loaded once for
/// all of them (docs/lab/nirc-speed.md, "Several queries per invocation").
pub const LANE_QUERIES: u32 = 4;

/// Where each matrix starts in one predictor's staged weights (vec4s), and the vec4s of one
/// predictor: matrix m as W^T by output quads, lane_w[base_m + k * quads + q] = outputs
/// 4q..4q+3 of input k. Predictor `net` starts at net * the total.
pub fn lane_w_layout(layout: &ParameterLayout) -> (Vec<u32>, u32) {
    let mut bases = Vec::new();
    let mut total = 0;
    for m in &layout.matrices {
        bases.push(total);
        total += m.rows.div_ceil(4) * m.cols;
    }
    (bases, total)
}

/// Bytes of the uniform buffer holding both predictors' staged weights.
pub fn uniform_bytes(layout: &ParameterLayout) -> u32 {
    2 * lane_w_layout(layout).1 * 16
}

/// The generated module `package::nirc::lane`: the staged weights' binding and bases, the input
/// vector, `lane_inputs` (the encoding of one query, level by level with its constants) and
/// `lane_net` (the forward pass of the predictor whose weights start at `net_base`).
pub fn module(layout: &ParameterLayout, grid_textures: bool) -> String {
    let in_vec4 = layout.input_dims.div_ceil(4);
    let (bases, total) = lane_w_layout(layout);
    let mut s = String::from(
        "import package::nirc::encoding::{corners_at, corner_sum, direction_feature};\nimport package::nirc::grid::{corner_pair};\n\n",
    );
    let bases_text: Vec<String> = bases.iter().map(|b| format!("{b}u")).collect();
    s.push_str(&format!(
        "const LANE_W_VEC4: u32 = {total}u;\nconst LANE_BASE = array<u32, {}>({});\n@group(0) @binding(8) var<uniform> lane_w: array<vec4<f32>, {}>;\nstruct LaneIn {{ {} }}\nstruct LanePair {{ a: LaneIn, b: LaneIn }}\n\n",
        bases.len(),
        bases_text.join(", "),
        2 * total,
        (0..in_vec4).map(|i| format!("v{i}: vec4<f32>")).collect::<Vec<_>>().join(", ")
    ));
    s.push_str("fn lane_relu(v: vec4<f32>) -> vec4<f32> {\n    return select(vec4<f32>(0.0), v, v > vec4<f32>(0.0));\n}\n\n");
    s.push_str(&inputs(layout, grid_textures));
    s.push_str(&net(layout, &bases));
    s
}

/// `lane_inputs(p, dir, first_net, both)`: the network input of predictor `first_net` in `.a`
/// and, with `both`, of predictor 0 in `.b`, from one set of corners per level. With the grid
/// mirror (`grid_textures`, two features per level) each corner's two features are one texel.
fn inputs(layout: &ParameterLayout, grid_textures: bool) -> String {
    let f = layout.features_per_level;
    let slot = |i: u32| format!("v{}.{}", i / 4, XYZW[(i % 4) as usize]);
    let mut s = String::from(
        "fn lane_inputs(p: vec3<f32>, dir: vec3<f32>, first_net: u32, both: bool) -> LanePair {\n    var x: LanePair;\n",
    );
    for (l, level) in layout.levels.iter().enumerate() {
        s.push_str(&format!(
            "    {{\n        let c = corners_at(p, {}u, {}, {}u, {}u);\n",
            level.resolution, level.dense, level.table_size, level.offset
        ));
        if grid_textures {
            let (i, j) = (slot(l as u32 * f), slot(l as u32 * f + 1));
            s.push_str(&format!("        let a = corner_pair(first_net, c);\n        x.a.{i} = a.x;\n        x.a.{j} = a.y;\n        if both {{\n            let b = corner_pair(0u, c);\n            x.b.{i} = b.x;\n            x.b.{j} = b.y;\n        }}\n"));
        }
        for k in (0..f).filter(|_| !grid_textures) {
            let i = l as u32 * f + k;
            s.push_str(&format!("        x.a.{} = corner_sum(first_net, c, {k}u);\n        if both {{\n            x.b.{} = corner_sum(0u, c, {k}u);\n        }}\n", slot(i), slot(i)));
        }
        s.push_str("    }\n");
    }
    let base = layout.levels.len() as u32 * f;
    for i in 0..layout.direction_dims {
        s.push_str(&format!(
            "    x.a.{} = direction_feature(dir, {i}u);\n    x.b.{} = x.a.{};\n",
            slot(base + i),
            slot(base + i),
            slot(base + i)
        ));
    }
    s.push_str("    return x;\n}\n\n");
    s
}

/// `lane_net(net_base, x0, .., x{K-1}) -> LaneOut`: the forward pass of `LANE_QUERIES` queries at
/// once, each weight loaded once for all. Every layer loops over its output quads with the sum
/// over the layer's inputs unrolled (inputs in order); each quad lands in its named register
/// through a switch on the (uniform) quad index. ReLU on hidden layers; the outputs in .xyz.
fn net(layout: &ParameterLayout, bases: &[u32]) -> String {
    let kq = LANE_QUERIES;
    let fields: Vec<String> = (0..kq).map(|j| format!("o{j}: vec4<f32>")).collect();
    let params: Vec<String> = (0..kq).map(|j| format!("x{j}: LaneIn")).collect();
    let mut s = format!(
        "struct LaneOut {{ {} }}\n\nfn lane_net(net_base: u32, {}) -> LaneOut {{\n",
        fields.join(", "),
        params.join(", ")
    );
    let last = layout.matrices.len() - 1;
    for (m, (matrix, base)) in layout.matrices.iter().zip(bases).enumerate() {
        let quads = matrix.rows.div_ceil(4);
        let input = |k: u32, j: u32| {
            if m == 0 { format!("x{j}.v{}", k / 4) } else { format!("h{j}_{}_{}", m - 1, k / 4) }
        };
        if m < last {
            for q in 0..quads {
                for j in 0..kq {
                    s.push_str(&format!("    var h{j}_{m}_{q} = vec4<f32>(0.0);\n"));
                }
            }
        }
        s.push_str(&format!("    for (var q = 0u; q < {quads}u; q++) {{\n        let row = net_base + {base}u + q;\n"));
        for j in 0..kq {
            s.push_str(&format!("        var acc{j} = vec4<f32>(0.0);\n"));
        }
        for k in 0..matrix.cols {
            s.push_str(&format!("        let w{k} = lane_w[row + {}u];\n", k * quads));
            for j in 0..kq {
                s.push_str(&format!(
                    "        acc{j} += {}.{} * w{k};\n",
                    input(k, j),
                    XYZW[(k % 4) as usize]
                ));
            }
        }
        if m < last {
            s.push_str("        switch q {\n");
            for q in 0..quads {
                let sets: String =
                    (0..kq).map(|j| format!(" h{j}_{m}_{q} = lane_relu(acc{j});")).collect();
                s.push_str(&format!("            case {q}u: {{{sets} }}\n"));
            }
            s.push_str("            default: {}\n        }\n    }\n");
        } else {
            // The output layer has one quad.
            let accs: Vec<String> = (0..kq).map(|j| format!("acc{j}")).collect();
            let zeros: Vec<String> = (0..kq).map(|_| "vec4<f32>(0.0)".to_string()).collect();
            s.push_str(&format!(
                "        return LaneOut({});\n    }}\n    return LaneOut({});\n",
                accs.join(", "),
                zeros.join(", ")
            ));
        }
    }
    s.push_str("}\n");
    s
}

/// The generated module `package::nirc::lane_queries` of `infer_lane.wgsl`: `lane_infer(first, pr,
/// mode)` answers queries first, first + 64, .. (`LANE_QUERIES` of them) with one pass of each
/// predictor's layers; those past the end compute the last query again and write nothing.
pub fn queries_module() -> String {
    let kq = LANE_QUERIES;
    let wg = super::WORKGROUP_SIZE;
    let list = |f: &dyn Fn(u32) -> String| (0..kq).map(f).collect::<Vec<_>>().join(", ");
    let mut s = String::from(
        "import package::nirc::bindings::{call, hyper, queries};\nimport package::nirc::bindings_common::{normalize_to_bounds};\nimport package::nirc::lane::{LANE_W_VEC4, LaneOut, lane_inputs, lane_net};\nimport package::nirc::answer::{Predictors, write_predictions};\n\n",
    );
    s.push_str(&format!("const LANE_QUERIES: u32 = {kq}u;\n\nfn lane_infer(first: u32, pr: Predictors, mode: u32) {{\n    let last = call.n - 1u;\n"));
    for j in 0..kq {
        s.push_str(&format!(
            "    let i{j} = min(first + {}u, last);\n    let r{j} = queries[i{j}];\n    let x{j} = lane_inputs(normalize_to_bounds(hyper, r{j}.position.xyz), r{j}.direction.xyz, pr.first_net, pr.both);\n",
            j * wg
        ));
    }
    s.push_str(&format!(
        "    let f = lane_net(pr.first_net * LANE_W_VEC4, {});\n",
        list(&|j| format!("x{j}.a"))
    ));
    s.push_str(&format!(
        "    var g = LaneOut({});\n    if pr.both {{\n        g = lane_net(0u, {});\n    }}\n",
        list(&|_| "vec4<f32>(0.0)".into()),
        list(&|j| format!("x{j}.b"))
    ));
    for j in 0..kq {
        s.push_str(&format!("    if first + {}u <= last {{\n        write_predictions(i{j}, r{j}.position.xyz, mode, pr, f.o{j}.xyz, g.o{j}.xyz);\n    }}\n", j * wg));
    }
    s.push_str("}\n");
    s
}
