//! The passes' shader program.

use super::TerminationCache;
use super::gpu_types::{OWN_GROUP, TcParams, TcRecord, TcVertex};
use crate::gpu_decision::decision_module;
use render::compute;
use render::gpu_struct::GpuStruct;
use render::pass_library::PassLibrary;
use render::shader::{Module, Program};

impl TerminationCache {
    /// The passes' program: the shading library, TAA's primary attributes, the hash cache's
    /// keys and its `hc` parameters (binding 0 of this @group(2), its own module because
    /// hash_key.wgsl imports it from there), this cache's structs and other bindings, the
    /// decision, termination.wgsl.
    pub fn program() -> &'static Program {
        static PROGRAM: std::sync::OnceLock<Program> = std::sync::OnceLock::new();
        PROGRAM.get_or_init(|| {
            let taa_types = taa::types_module();
            let hc_types = hash_cache::types_module();
            let types = Module::generated(
                "package::termination_types",
                &[TcParams::WGSL, TcRecord::WGSL, TcVertex::WGSL],
            );
            let hc = compute::group_module_range(
                "package::hash_cache_bindings",
                2,
                &OWN_GROUP,
                0..1,
                &[&hc_types],
            );
            let bindings = compute::group_module_range(
                "package::termination_bindings",
                2,
                &OWN_GROUP,
                1..OWN_GROUP.len(),
                &[&taa_types, &types],
            );
            PassLibrary::program(
                [
                    taa_types,
                    taa::primary_module(),
                    hc_types,
                    hc,
                    types,
                    bindings,
                    hash_cache::key_module(),
                    decision_module(),
                ],
                [render::wgsl_file!("termination.wgsl")],
            )
        })
    }
}
