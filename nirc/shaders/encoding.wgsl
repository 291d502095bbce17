// Input encoding (CPU mirror: src/cpu/encoding.rs): multi-resolution hash grid of the position
// with trilinear interpolation, then the direction (identity or real spherical harmonics).
// Needs from the pass: `hyper`, `fn table(net, i) -> f32` and the private `acts` array.

struct Corners {
    index: array<u32, 8>,
    weight: array<f32, 8>,
}

// The 8 vertices of the cell around the normalised position p on one level: the parameter
// index of each vertex's first feature and its trilinear weight.
fn level_corners(level: u32, p: vec3<f32>) -> Corners {
    let res = level_resolution[level];
    var cell = vec3<u32>(0u);
    var frac = vec3<f32>(0.0);
    for (var a = 0u; a < 3u; a++) {
        let x = p[a] * f32(res);
        // The upper face (p = 1) belongs to the last cell, with fraction 1.
        cell[a] = min(u32(floor(x)), res - 1u);
        frac[a] = x - f32(cell[a]);
    }
    var out: Corners;
    for (var c = 0u; c < 8u; c++) {
        let d = vec3<u32>(c & 1u, (c >> 1u) & 1u, c >> 2u);
        let v = cell + d;
        var entry: u32;
        if level_dense[level] == 1u {
            let side = res + 1u;
            entry = v.x + v.y * side + v.z * side * side;
        } else {
            entry = spatial_hash(v) & (level_table_size[level] - 1u);
        }
        let w = select(vec3<f32>(1.0) - frac, frac, d == vec3<u32>(1u));
        out.index[c] = level_offset[level] + entry * FEATURES;
        out.weight[c] = w.x * w.y * w.z;
    }
    return out;
}

fn encode_direction(d: vec3<f32>) {
    let x = d.x;
    let y = d.y;
    let z = d.z;
    let b = LEVELS * FEATURES;
    if DIR_KIND == 1u {
        acts[b] = x;
        acts[b + 1u] = y;
        acts[b + 2u] = z;
    } else if DIR_KIND == 2u {
        acts[b] = 0.2820948;
        if DIR_BANDS >= 2u {
            acts[b + 1u] = -0.48860252 * y;
            acts[b + 2u] = 0.48860252 * z;
            acts[b + 3u] = -0.48860252 * x;
        }
        if DIR_BANDS >= 3u {
            acts[b + 4u] = 1.0925484 * x * y;
            acts[b + 5u] = -1.0925484 * y * z;
            acts[b + 6u] = 0.9461747 * z * z - 0.31539157;
            acts[b + 7u] = -1.0925484 * x * z;
            acts[b + 8u] = 0.5462742 * (x * x - y * y);
        }
    }
}

// Writes the network input of predictor `net` (0 = High-LR, 1 = EMA) into acts[0..IN_DIMS).
fn encode_input(net: u32, position: vec3<f32>, direction: vec3<f32>) {
    let p = normalize_to_bounds(hyper, position);
    for (var l = 0u; l < LEVELS; l++) {
        let corners = level_corners(l, p);
        for (var k = 0u; k < FEATURES; k++) {
            var acc = 0.0;
            for (var c = 0u; c < 8u; c++) {
                acc += corners.weight[c] * table(net, corners.index[c] + k);
            }
            acts[l * FEATURES + k] = acc;
        }
    }
    encode_direction(direction);
}
