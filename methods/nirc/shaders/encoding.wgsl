// Input encoding (CPU mirror: src/cpu/encoding.rs): multi-resolution hash grid of the position
// with trilinear interpolation, then the direction (identity or real spherical harmonics).
// Needs from the pass: `hyper` and `fn table(net, i) -> f32`.

import package::nirc::config::{DIR_KIND, FEATURES, level_dense, level_offset, level_resolution, level_table_size};
import package::nirc::bindings_common::{spatial_hash};
import package::nirc::weights::{table, weight};

struct Corners {
    index: array<u32, 8>,
    weight: array<f32, 8>,
}

// The 8 vertices of the cell around the normalised position p on one level: the parameter
// index of each vertex's first feature and its trilinear weight.
fn level_corners(level: u32, p: vec3<f32>) -> Corners {
    return corners_at(p, level_resolution[level], level_dense[level] == 1u, level_table_size[level], level_offset[level]);
}

// The cell of a level that holds p, and p's fractions inside it.
struct Cell {
    cell: vec3<u32>,
    frac: vec3<f32>,
}

struct Corner {
    index: u32,
    weight: f32,
}

fn cell_at(p: vec3<f32>, res: u32) -> Cell {
    var out: Cell;
    for (var a = 0u; a < 3u; a++) {
        let x = p[a] * f32(res);
        // The upper face (p = 1) belongs to the last cell, with fraction 1.
        out.cell[a] = min(u32(floor(x)), res - 1u);
        out.frac[a] = x - f32(out.cell[a]);
    }
    return out;
}

// Vertex c (bits x, y, z) of a cell: the parameter index of its first feature and its
// trilinear weight.
fn cell_corner(cell: Cell, c: u32, res: u32, dense: bool, table_size: u32, offset: u32) -> Corner {
    let d = vec3<u32>(c & 1u, (c >> 1u) & 1u, c >> 2u);
    let v = cell.cell + d;
    var entry: u32;
    if dense {
        let side = res + 1u;
        entry = v.x + v.y * side + v.z * side * side;
    } else {
        entry = spatial_hash(v) & (table_size - 1u);
    }
    let w = select(vec3<f32>(1.0) - cell.frac, cell.frac, d == vec3<u32>(1u));
    return Corner(offset + entry * FEATURES, w.x * w.y * w.z);
}

// Vertex c of the cell around p on one level (a loop over c then keeps no array of corners:
// lavapipe puts a dynamically indexed private array in memory).
fn level_corner(level: u32, cell: Cell, c: u32) -> Corner {
    return cell_corner(cell, c, level_resolution[level], level_dense[level] == 1u, level_table_size[level], level_offset[level]);
}

// level_corners with the level's resolution, density, table size and offset given (the
// generated register-form inference passes them as constants, so nothing is looked up).
fn corners_at(p: vec3<f32>, res: u32, dense: bool, table_size: u32, offset: u32) -> Corners {
    let cell = cell_at(p, res);
    var out: Corners;
    for (var c = 0u; c < 8u; c++) {
        let corner = cell_corner(cell, c, res, dense, table_size, offset);
        out.index[c] = corner.index;
        out.weight[c] = corner.weight;
    }
    return out;
}

// Feature i (< DIR_DIMS) of the direction encoding.
fn direction_feature(d: vec3<f32>, i: u32) -> f32 {
    if DIR_KIND == 1u {
        return d[i];
    }
    switch i {
        case 0u: { return 0.2820948; }
        case 1u: { return -0.48860252 * d.y; }
        case 2u: { return 0.48860252 * d.z; }
        case 3u: { return -0.48860252 * d.x; }
        case 4u: { return 1.0925484 * d.x * d.y; }
        case 5u: { return -1.0925484 * d.y * d.z; }
        case 6u: { return 0.9461747 * d.z * d.z - 0.31539157; }
        case 7u: { return -1.0925484 * d.x * d.z; }
        case 8u: { return 0.5462742 * (d.x * d.x - d.y * d.y); }
        default: { return 0.0; }
    }
}

// Feature k of one level from predictor `net`'s table: the trilinear sum over the corners.
fn corner_sum(net: u32, corners: Corners, k: u32) -> f32 {
    var acc = 0.0;
    for (var c = 0u; c < 8u; c++) {
        acc += corners.weight[c] * table(net, corners.index[c] + k);
    }
    return acc;
}
