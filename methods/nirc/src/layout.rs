//! Where every parameter lives in the one flat parameter vector shared by the CPU reference and
//! the GPU: MLP matrices first (row-major [out][in], layer by layer), then the hash-grid tables
//! level by level (entry-major, F features per entry). Both regions end on a multiple of 4
//! parameters (zero padding), so that no quad of parameters straddles them.

use crate::config::NircCacheSettings;

/// One hash-grid level.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct GridLevel {
    pub resolution: u32,
    /// Entries in this level's table: (resolution+1)^3 if dense, else 2^log2_table_size.
    pub table_size: u32,
    /// Index of the level's first parameter in the flat vector.
    pub offset: u32,
    pub dense: bool,
}

/// One weight matrix of the MLP.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Matrix {
    pub rows: u32,
    pub cols: u32,
    pub offset: u32,
}

#[derive(Clone, Debug, PartialEq, Eq)]
pub struct ParameterLayout {
    pub levels: Vec<GridLevel>,
    pub features_per_level: u32,
    /// Hash-grid features + direction encoding.
    pub input_dims: u32,
    pub direction_dims: u32,
    pub width: u32,
    pub hidden_layers: u32,
    /// hidden_layers + 1 matrices: input->width, (width->width)*, width->3.
    pub matrices: Vec<Matrix>,
    /// The MLP matrices' parameters, rounded up to a multiple of 4 (where the grid starts).
    pub mlp_params: u32,
    /// Every parameter, rounded up to a multiple of 4.
    pub total_params: u32,
}

pub const OUTPUT_DIMS: u32 = 3;

impl ParameterLayout {
    pub fn new(config: &NircCacheSettings) -> Self {
        let e = &config.encoding;
        let direction_dims = config.direction.dims();
        let input_dims = e.levels * e.features_per_level + direction_dims;
        let width = config.network.width;
        let hidden = config.network.hidden_layers;
        let mut matrices = Vec::new();
        let mut offset = 0u32;
        for k in 0..=hidden {
            let cols = if k == 0 { input_dims } else { width };
            let rows = if k == hidden { OUTPUT_DIMS } else { width };
            matrices.push(Matrix { rows, cols, offset });
            offset += rows * cols;
        }
        // The MLP region and the whole vector are rounded up to whole quads (unused, zero
        // parameters): the Adam and EMA passes read four parameters per load, and a quad must
        // not straddle the MLP and the grid, whose gradients live in different buffers.
        offset = offset.next_multiple_of(4);
        let mlp_params = offset;
        let max_table = 1u64 << e.log2_table_size;
        let mut levels = Vec::new();
        for l in 0..e.levels {
            // f64 so that every platform gets the same integer resolutions.
            let resolution = ((e.base_resolution as f64) * (e.growth_factor as f64).powi(l as i32))
                .floor()
                .max(1.0) as u64;
            let dense_size = (resolution + 1).pow(3);
            let dense = dense_size <= max_table;
            let table_size = if dense { dense_size } else { max_table } as u32;
            levels.push(GridLevel {
                resolution: resolution.min(u32::MAX as u64 / 2) as u32,
                table_size,
                offset,
                dense,
            });
            offset += table_size * e.features_per_level;
        }
        Self {
            levels,
            features_per_level: e.features_per_level,
            input_dims,
            direction_dims,
            width,
            hidden_layers: hidden,
            matrices,
            mlp_params,
            total_params: offset.next_multiple_of(4),
        }
    }

    /// The MLP matrices' weights, without the quad padding after them.
    pub fn mlp_weights(&self) -> u32 {
        self.matrices.iter().map(|m| m.rows * m.cols).sum()
    }

    /// Parameters of the hash-grid tables, without the quad padding at the end.
    pub fn grid_table_params(&self) -> u32 {
        self.levels.iter().map(|l| l.table_size * self.features_per_level).sum()
    }

    /// Parameters after the MLP region: the grid tables and the quad padding.
    pub fn grid_params(&self) -> u32 {
        self.total_params - self.mlp_params
    }

    /// Per-record floats of the training scratch: inputs (padded to a quad) + hidden
    /// activations, then the pre-activation gradients of every hidden layer and of the output.
    /// The padding lets the tiled pass move whole quads (vec4) where the width is a multiple of 4.
    pub fn activation_floats(&self) -> u32 {
        self.input_stride() + self.hidden_layers * self.width
    }
    pub fn delta_floats(&self) -> u32 {
        self.hidden_layers * self.width + OUTPUT_DIMS
    }
    /// Where the first hidden activation starts in a record's scratch slot.
    pub fn input_stride(&self) -> u32 {
        self.input_dims.next_multiple_of(4)
    }
    /// Floats of one record's scratch slot, a whole number of quads.
    pub fn scratch_stride(&self) -> u32 {
        (self.activation_floats() + self.delta_floats()).next_multiple_of(4)
    }

    /// Multiply-adds of one forward pass of the MLP (the FLOP count is twice this).
    pub fn forward_macs(&self) -> u64 {
        self.matrices.iter().map(|m| m.rows as u64 * m.cols as u64).sum()
    }

    /// An upper bound on the loop iterations one invocation of the heaviest per-query pass
    /// runs: a training thread (encode, forward, backward, encoding gradient, scratch
    /// clearing) or a blending inference thread (encode, two forwards), plus its share of the
    /// workgroup weight copy. Drivers that cap it (llvmpipe) are checked against this.
    pub fn loop_iterations_per_invocation(&self, workgroup_size: u32) -> u64 {
        let matrix_loops =
            |m: &Matrix| m.rows as u64 * m.cols as u64 + m.rows.max(m.cols) as u64 + 1;
        let forward: u64 = self.matrices.iter().map(matrix_loops).sum::<u64>() + 1;
        let encoding = self.levels.len() as u64 * (8 * self.features_per_level as u64 + 8 + 3);
        let copy = (2 * self.mlp_params as u64).div_ceil(workgroup_size.max(1) as u64);
        let train = encoding * 2
            + forward * 2
            + (self.activation_floats() + self.delta_floats()) as u64
            + 3;
        let infer = encoding + forward * 2;
        train.max(infer) + copy
    }
}

/// The spatial hash of instant-ngp: coordinates times large primes, xor-ed.
pub fn spatial_hash(x: u32, y: u32, z: u32) -> u32 {
    x ^ y.wrapping_mul(2_654_435_761) ^ z.wrapping_mul(805_459_861)
}
