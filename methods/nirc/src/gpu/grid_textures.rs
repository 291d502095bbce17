//! The hash-grid tables of both predictors mirrored in `rgba32float` storage textures, one texel
//! per quad of parameters (two entries of two features), for the register form on CPU adapters.
//!
//! Why: lavapipe reads a storage texel inline, in a gathered load, where a storage-buffer load at
//! a per-invocation address is a loop over the SIMD lanes (render/src/texel_table.rs,
//! `examples/load_probe.rs`). The encoding's table reads are about half of the register form's
//! inference. The buffers stay the parameters' home (Adam, the EMA, readback, the MLP
//! weights); the textures are written where the buffers are (the initial upload, then Adam's
//! `apply` and `ema_update` for every grid quad), and only the encodings of the tiled training
//! pass and of the register-form inference read them.
//!
//! Texel t holds parameters MLP_PARAMS + 4t .. + 4t + 3, at (t % width, t / width): a grid quad
//! is one store, and an entry's two features are one half of a fetched texel.

use crate::layout::ParameterLayout;
use crate::state::CacheState;
use render::gpu::Gpu;

/// Texels per row at most (the WebGPU default limit is 8192).
const MAX_WIDTH: u32 = 4096;

/// Bindings of the read textures in the passes that read them (train_bindings, infer_bindings)
/// and of the write textures in adam_ema.wgsl.
pub const READ_BINDINGS: [u32; 2] = [12, 13];
pub const WRITE_BINDINGS: [u32; 2] = [9, 10];

pub struct GridTextures {
    pub width: u32,
    /// [High-LR (params), EMA], as `TextureView`s for binding.
    pub views: [wgpu::TextureView; 2],
}

/// Texels of the mirror: one per grid quad (the layout pads the grid to quads).
fn texels(layout: &ParameterLayout) -> u32 {
    layout.grid_params() / 4
}

/// The texture width if the register form can use the mirror on this adapter: two features per
/// level, `rgba32float` storage textures, and a texture within the adapter's size limit.
/// Otherwise (and in the other forms) the passes read the grid from the parameter buffers.
pub fn width_for(gpu: &Gpu, layout: &ParameterLayout) -> Option<u32> {
    let max = gpu.limits.max_texture_dimension_2d;
    let width = MAX_WIDTH.min(max);
    let fits = texels(layout).div_ceil(width) <= max;
    let storage = gpu
        .adapter
        .get_texture_format_features(wgpu::TextureFormat::Rgba32Float)
        .allowed_usages
        .contains(wgpu::TextureUsages::STORAGE_BINDING);
    (layout.features_per_level == 2 && fits && storage).then_some(width)
}

impl GridTextures {
    /// Both textures, filled from `state`.
    pub fn new(gpu: &Gpu, layout: &ParameterLayout, state: &CacheState, width: u32) -> Self {
        let n = texels(layout);
        let height = n.div_ceil(width);
        let grid = layout.mlp_params as usize..layout.total_params as usize;
        let views = [
            ("nirc grid mirror (High-LR)", &state.params[grid.clone()]),
            ("nirc grid mirror (EMA)", &state.ema[grid]),
        ]
        .map(|(label, values)| {
            let texture = gpu.device.create_texture(&wgpu::TextureDescriptor {
                label: Some(label),
                size: wgpu::Extent3d { width, height, depth_or_array_layers: 1 },
                mip_level_count: 1,
                sample_count: 1,
                dimension: wgpu::TextureDimension::D2,
                format: wgpu::TextureFormat::Rgba32Float,
                usage: wgpu::TextureUsages::STORAGE_BINDING | wgpu::TextureUsages::COPY_DST,
                view_formats: &[],
            });
            // Whole rows, then the last row's remaining texels.
            let bytes: &[u8] = bytemuck::cast_slice(values);
            let row_bytes = width as usize * 16;
            let full = n / width;
            let write = |y: u32, texels: u32, data: &[u8]| {
                gpu.queue.write_texture(
                    wgpu::TexelCopyTextureInfo {
                        texture: &texture,
                        mip_level: 0,
                        origin: wgpu::Origin3d { x: 0, y, z: 0 },
                        aspect: wgpu::TextureAspect::All,
                    },
                    data,
                    wgpu::TexelCopyBufferLayout {
                        offset: 0,
                        bytes_per_row: Some(texels * 16),
                        rows_per_image: None,
                    },
                    wgpu::Extent3d {
                        width: texels,
                        height: if y < full { full } else { 1 },
                        depth_or_array_layers: 1,
                    },
                );
            };
            if full > 0 {
                write(0, width, &bytes[..full as usize * row_bytes]);
            }
            let rest = n - full * width;
            if rest > 0 {
                write(full, rest, &bytes[full as usize * row_bytes..]);
            }
            texture.create_view(&wgpu::TextureViewDescriptor::default())
        });
        Self { width, views }
    }
}

/// `package::nirc::grid`: `GRID_PAIRS` and `corner_pair(net, corners)`, the trilinear sums of a
/// level's two features (FEATURES = 2), from the textures when `width` is given, else from the
/// parameter buffers (then `GRID_PAIRS` is false and the passes read feature by feature).
pub fn read_module(width: Option<u32>) -> String {
    let common = "import package::nirc::encoding::{Corners};\n";
    match width {
        Some(w) => format!(
            "{common}import package::nirc::config::{{MLP_PARAMS}};\n\
             const GRID_PAIRS: bool = true;\n\
             @group(0) @binding({}) var grid_params: texture_storage_2d<rgba32float, read>;\n\
             @group(0) @binding({}) var grid_ema: texture_storage_2d<rgba32float, read>;\n\
             fn grid_texel(net: u32, i: u32) -> vec2<f32> {{\n    let t = (i - MLP_PARAMS) / 4u;\n    let at = vec2<u32>(t % {w}u, t / {w}u);\n    var q: vec4<f32>;\n    if net == 0u {{\n        q = textureLoad(grid_params, at);\n    }} else {{\n        q = textureLoad(grid_ema, at);\n    }}\n    return select(q.xy, q.zw, (i & 2u) != 0u);\n}}\n\
             // Features 0 and 1 of one level: corner_sum of each, the same sums in the same order.\n\
             fn corner_pair(net: u32, corners: Corners) -> vec2<f32> {{\n    var acc = vec2<f32>(0.0);\n    for (var c = 0u; c < 8u; c++) {{\n        acc += corners.weight[c] * grid_texel(net, corners.index[c]);\n    }}\n    return acc;\n}}\n",
            READ_BINDINGS[0], READ_BINDINGS[1]
        ),
        None => format!(
            "{common}const GRID_PAIRS: bool = false;\n\
             fn corner_pair(net: u32, corners: Corners) -> vec2<f32> {{\n    return vec2<f32>(0.0);\n}}\n"
        ),
    }
}

/// `package::nirc::grid_write`: `mirror_params(q, v)` and `mirror_ema(q, v)` store grid quad q
/// (q >= MLP_PARAMS / 4) of that predictor in its texel; without the textures they do nothing.
pub fn write_module(width: Option<u32>) -> String {
    match width {
        Some(w) => format!(
            "import package::nirc::config::{{MLP_PARAMS}};\n\
             @group(0) @binding({}) var grid_params_out: texture_storage_2d<rgba32float, write>;\n\
             @group(0) @binding({}) var grid_ema_out: texture_storage_2d<rgba32float, write>;\n\
             fn mirror_params(q: u32, v: vec4<f32>) {{\n    let t = q - MLP_PARAMS / 4u;\n    textureStore(grid_params_out, vec2<u32>(t % {w}u, t / {w}u), v);\n}}\n\
             fn mirror_ema(q: u32, v: vec4<f32>) {{\n    let t = q - MLP_PARAMS / 4u;\n    textureStore(grid_ema_out, vec2<u32>(t % {w}u, t / {w}u), v);\n}}\n",
            WRITE_BINDINGS[0], WRITE_BINDINGS[1]
        ),
        None => {
            "fn mirror_params(q: u32, v: vec4<f32>) {}\nfn mirror_ema(q: u32, v: vec4<f32>) {}\n"
                .to_string()
        }
    }
}
