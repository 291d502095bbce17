//! The media shader library as WESL modules: the generated structs and the medium's @group(0),
//! then the estimator files (each imports what it uses); a pass adds its own structs, its
//! @group(1) and its entry-point file.

use render::compute::BufferBinding;
use render::gpu_struct::GpuStruct;
use render::shader::{Module, Program};

use super::medium::{MediumParams, RaySegment};

/// The library's modules: structs, the medium's bindings, the estimator files.
pub fn modules() -> Vec<Module> {
    modules_at(0)
}

/// [`modules`] with the medium bound as @group(`group`) (3 in passes on the path tracer's
/// scene, which holds groups 0 and 1).
pub fn modules_at(group: u32) -> Vec<Module> {
    let types = Module::generated("package::media::types", &[MediumParams::WGSL, RaySegment::WGSL]);
    let bindings = render::compute::group_module(
        "package::media::medium_bindings",
        group,
        &super::medium::BINDINGS,
        &[&types],
    );
    vec![
        types,
        bindings,
        render::wgsl_file!("media_rng.wgsl"),
        render::wgsl_file!("media_grid.wgsl"),
        render::wgsl_file!("media_dda.wgsl"),
        render::wgsl_file!("media_tracking.wgsl"),
        render::wgsl_file!("media_optical_depth.wgsl"),
        render::wgsl_file!("media_jackknife.wgsl"),
        render::wgsl_file!("media_mis.wgsl"),
        render::wgsl_file!("media_estimators.wgsl"),
    ]
}

/// A pass's program: the library, the pass's struct `params_wgsl` (`package::media::NAME_types`),
/// its @group(1) (`package::media::NAME_bindings`) and its entry-point file.
pub fn program(name: &str, params_wgsl: &str, own: &[BufferBinding], entry: Module) -> Program {
    let library = modules();
    let types = Module::generated(&format!("package::media::{name}_types"), &[params_wgsl]);
    // Its bindings may name the library's structs too (`array<RaySegment>`).
    let bindings = render::compute::group_module(
        &format!("package::media::{name}_bindings"),
        1,
        own,
        &[&types, &library[0]],
    );
    Program::new(library).with([types, bindings]).entry(entry)
}
