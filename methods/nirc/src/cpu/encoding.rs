//! CPU reference of the input encoding: multi-resolution hash grid of the position with
//! trilinear interpolation, then the direction encoding.

use super::real::Real;
use crate::bounds::SceneBounds;
use crate::config::DirectionEncoding;
use crate::layout::{ParameterLayout, spatial_hash};

/// The 8 grid vertices around a point on one level: parameter index of each vertex's first
/// feature and its trilinear weight. Kept for the backward pass.
#[derive(Clone, Copy, Debug)]
pub struct LevelCorners {
    pub param_index: [u32; 8],
    pub weight: [f32; 8],
}

/// Finds the 8 vertices of the cell containing the normalised position `p` on every level.
pub fn grid_corners(layout: &ParameterLayout, p: [f32; 3]) -> Vec<LevelCorners> {
    let f = layout.features_per_level;
    layout
        .levels
        .iter()
        .map(|level| {
            let res = level.resolution;
            let mut cell = [0u32; 3];
            let mut frac = [0f32; 3];
            for a in 0..3 {
                let x = p[a] * res as f32;
                // The upper face (p = 1) belongs to the last cell, with fraction 1.
                cell[a] = (x.floor() as u32).min(res - 1);
                frac[a] = x - cell[a] as f32;
            }
            let mut out = LevelCorners { param_index: [0; 8], weight: [0.0; 8] };
            for c in 0..8u32 {
                let d = [c & 1, (c >> 1) & 1, c >> 2];
                let v = [cell[0] + d[0], cell[1] + d[1], cell[2] + d[2]];
                let entry = if level.dense {
                    let side = res + 1;
                    v[0] + v[1] * side + v[2] * side * side
                } else {
                    spatial_hash(v[0], v[1], v[2]) & (level.table_size - 1)
                };
                let w = |a: usize| if d[a] == 1 { frac[a] } else { 1.0 - frac[a] };
                out.param_index[c as usize] = level.offset + entry * f;
                out.weight[c as usize] = w(0) * w(1) * w(2);
            }
            out
        })
        .collect()
}

/// Real spherical harmonics of the first `bands` bands (1..=3) of a unit direction.
pub fn spherical_harmonics(bands: u32, d: [f32; 3]) -> Vec<f32> {
    let [x, y, z] = d;
    let mut out = vec![0.282_094_8];
    if bands >= 2 {
        out.extend([-0.488_602_52 * y, 0.488_602_52 * z, -0.488_602_52 * x]);
    }
    if bands >= 3 {
        out.extend([
            1.092_548_4 * x * y,
            -1.092_548_4 * y * z,
            0.946_174_7 * z * z - 0.315_391_57,
            -1.092_548_4 * x * z,
            0.546_274_2 * (x * x - y * y),
        ]);
    }
    out
}

pub fn encode_direction(encoding: DirectionEncoding, d: [f32; 3]) -> Vec<f32> {
    match encoding {
        DirectionEncoding::None => Vec::new(),
        DirectionEncoding::Identity => d.to_vec(),
        DirectionEncoding::SphericalHarmonics { bands } => spherical_harmonics(bands, d),
    }
}

/// The network input for a query: L*F interpolated grid features, then the direction encoding.
pub fn encode<T: Real>(
    layout: &ParameterLayout,
    direction_encoding: DirectionEncoding,
    params: &[T],
    bounds: &SceneBounds,
    position: [f32; 3],
    direction: [f32; 3],
) -> (Vec<T>, Vec<LevelCorners>) {
    let corners = grid_corners(layout, bounds.normalize(position));
    let f = layout.features_per_level as usize;
    let mut input = Vec::with_capacity(layout.input_dims as usize);
    for level in &corners {
        for k in 0..f {
            let mut acc = T::zero();
            for c in 0..8 {
                acc += T::from_f32(level.weight[c]) * params[level.param_index[c] as usize + k];
            }
            input.push(acc);
        }
    }
    input.extend(encode_direction(direction_encoding, direction).into_iter().map(T::from_f32));
    (input, corners)
}
