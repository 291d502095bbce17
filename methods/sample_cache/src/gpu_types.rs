//! The structs and header words the passes share with the WGSL.

/// Header words of the indirect arguments (`SSC_RETRACE_ARGS`, `SSC_SHADE_ARGS`).
pub(crate) const RETRACE_ARGS_WORD: u64 = 35;
pub(crate) const SHADE_ARGS_WORD: u64 = 38;

pub(crate) const HEADER_WORDS: u64 = 48;
/// Words per pixel of `pixel_atomics` (`SSC_ATOMICS`).
pub(crate) const PIXEL_ATOMICS: u64 = 5;
pub(crate) const AUDIT_WORD: u64 = 32;

render::gpu_struct! {
    /// The cache's parameters (`ssc`, @group(2) binding 0).
    pub struct SscParams {
        pub width: u32 => "u32",
        pub height: u32 => "u32",
        /// N, slots per pixel.
        pub slots: u32 => "u32",
        pub frame: u32 => "u32",
        /// 0 single, 1 multi, 2 adaptive.
        pub retrace: u32 => "u32",
        /// 0 uniform, 1 adaptive.
        pub shading: u32 => "u32",
        /// Side of the base-rate block, pixels.
        pub base_block: u32 => "u32",
        /// M, buckets of the importance histogram.
        pub buckets: u32 => "u32",
        pub n_target: f32 => "f32",
        pub delta: f32 => "f32",
        pub epsilon0: f32 => "f32",
        pub epsilon1: f32 => "f32",
        /// Minimum blend weight.
        pub alpha: f32 => "f32",
        /// Dynamic shading budget, samples.
        pub shading_budget: f32 => "f32",
        /// φ, the angle of a pixel's diagonal.
        pub pixel_diagonal_angle: f32 => "f32",
        /// 1: App. C's α_min from the material's roughness instead of `alpha`.
        pub roughness_alpha: u32 => "u32",
    }
}

render::gpu_struct! {
    /// Per output pixel: reconstructed radiance, motion (pixels, now -> previous frame), trace
    /// flags and rays traced.
    #[derive(Default)]
    pub struct SscPixel {
        pub radiance: [f32; 4] => "vec4f",
        pub motion: [f32; 2] => "vec2f",
        /// Bit 0: base-rate pixel, bit 1: flagged by the slope test, bit 2: hole.
        pub flags: u32 => "u32",
        pub rays: u32 => "u32",
    }
}

/// The former name of [`SscPixel`].
pub type GpuPixel = SscPixel;

pub const FLAG_BASE: u32 = 1;
pub const FLAG_SLOPE: u32 = 2;
pub const FLAG_HOLE: u32 = 4;
