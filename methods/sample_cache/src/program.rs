//! The passes' shader program and the cache's own bind group.

use crate::gpu_types::{SscParams, SscPixel};
use crate::storage;
use render::compute::BufferBinding;
use render::gpu_struct::GpuStruct;
use render::pass_library::PassLibrary;
use render::shader::{Module, Program};

/// The cache's own @group(2), declared into its WGSL: params, source mask and slots (read),
/// then pixel atomics, destination slots and mask, work lists, output, and the inputs of a TAA
/// resolve over the image (colour, closest visible sample's primary attributes).
pub(crate) const OWN_GROUP: [BufferBinding; 11] = [
    BufferBinding::read("ssc", "SscParams"),
    BufferBinding::read("src_mask", "array<u32>"),
    BufferBinding::read("src_slots", "array<SscSlot>"),
    // SSC_ATOMICS words per pixel: the reserved mask and the farthest visible depth (gather_main),
    // the retrace results (bits 0-15: visible, 16-31: traced), and the closest visible sample's
    // depth and Δn (closest_main).
    BufferBinding::read_write("pixel_atomics", "array<atomic<u32>>"),
    BufferBinding::read_write("dst_slots", "array<SscSlot>"),
    BufferBinding::read_write("dst_mask", "array<u32>"),
    BufferBinding::read_write("ssc_work", "array<atomic<u32>>"),
    BufferBinding::read_write("ssc_out", "array<SscPixel>"),
    // The reconstruction again in the layouts `Taa::resolve_external` copies from.
    BufferBinding::read_write("ssc_colour", "array<vec4f>"),
    BufferBinding::read_write("ssc_primary", "array<TaaPrimary>"),
    // The reservation's keys, N per pixel (layered as the slots): the complement of the
    // lowest keys that reached the pixel, in order (reproject.wgsl).
    BufferBinding::read_write("reserve_keys", "array<atomic<u32>>"),
];

/// The cache passes' program: the shading library, the cache's structs and @group(2), its
/// storage, slope and selection modules, and one entry-point file per stage's passes.
pub fn program() -> &'static Program {
    static PROGRAM: std::sync::OnceLock<Program> = std::sync::OnceLock::new();
    PROGRAM.get_or_init(|| {
        let types = Module::generated(
            "package::sample_cache_types",
            &[SscParams::WGSL, storage::SscSlot::WGSL, SscPixel::WGSL],
        );
        let taa_types = taa::types_module();
        let bindings = render::compute::group_module(
            "package::sample_cache_bindings",
            2,
            &OWN_GROUP,
            &[&types, &taa_types],
        );
        PassLibrary::program(
            [
                types,
                taa_types,
                taa::primary_module(),
                bindings,
                render::wgsl_file!("storage.wgsl"),
                render::wgsl_file!("slope.wgsl"),
                render::wgsl_file!("selection.wgsl"),
            ],
            [
                render::wgsl_file!("reproject.wgsl"),
                render::wgsl_file!("retrace.wgsl"),
                render::wgsl_file!("shading_rate.wgsl"),
                render::wgsl_file!("shade.wgsl"),
                render::wgsl_file!("list_dispatch.wgsl"),
                render::wgsl_file!("reconstruct.wgsl"),
            ],
        )
    })
}
