//! WGSL modules (render::shader): imports resolve across files and generated modules, entry
//! points keep their names, and a wrong import is an error that names the module.

use render::compute::{self, BufferBinding};
use render::shader::{Module, Program};

fn module(path: &str, source: &str) -> Module {
    Module::generated(path, &[source])
}

#[test]
fn imports_resolve_and_entry_points_keep_their_names() {
    let program = Program::new(vec![module("package::a", "const SCALE: f32 = 2.0;\nfn scaled(x: f32) -> f32 { return x * SCALE; }\n")])
        .entry(module("package::main", "import package::a::{scaled};\n@compute @workgroup_size(1) fn main_entry() { let y = scaled(1.0); }\n"));
    let linked = program.compose().expect("links");
    assert_eq!(linked.len(), 1);
    let wgsl = &linked[0];
    assert!(!wgsl.contains("import "), "imports are resolved:\n{wgsl}");
    assert!(wgsl.contains("fn main_entry("), "the entry point keeps its name:\n{wgsl}");
    // The imported function and the constant it uses come along (under mangled names).
    assert_eq!(wgsl.matches("fn ").count(), 2, "{wgsl}");
    assert!(wgsl.contains("SCALE"), "{wgsl}");
    naga::front::wgsl::parse_str(wgsl).expect("valid WGSL");
}

#[test]
fn a_missing_import_names_the_module() {
    let program = Program::new(vec![module("package::a", "fn f() {}\n")]).entry(module(
        "package::main",
        "import package::a::{g};\n@compute @workgroup_size(1) fn main() { g(); }\n",
    ));
    let err = program.compose().expect_err("g is not in package::a").to_string();
    assert!(err.contains("package::main") && err.contains('g'), "{err}");
    let program = Program::new(vec![]).entry(module(
        "package::main",
        "import package::nowhere::{g};\n@compute @workgroup_size(1) fn main() { g(); }\n",
    ));
    let err = program.compose().expect_err("no such module").to_string();
    assert!(err.contains("nowhere"), "{err}");
}

#[test]
fn a_group_module_imports_the_structs_its_bindings_name() {
    let types =
        module("package::types", "struct Params { n: u32, p0: f32 }\nstruct Slot { v: vec4f }\n");
    let group = [
        BufferBinding::read("params", "Params"),
        BufferBinding::read_write("slots", "array<Slot>"),
        BufferBinding::read_write("counts", "array<atomic<u32>>"),
    ];
    let bindings = compute::group_module("package::bindings", 2, &group, &[&types]);
    assert!(
        bindings.source.contains("import package::types::{Params, Slot};"),
        "{}",
        bindings.source
    );
    assert!(
        bindings
            .source
            .contains("@group(2) @binding(1) var<storage, read_write> slots: array<Slot>;"),
        "{}",
        bindings.source
    );
    // A struct member ending in a digit (naga_oil could not import it) survives the link.
    let program = Program::new(vec![types, bindings]).entry(module(
        "package::main",
        "import package::bindings::{params, slots, counts};\n@compute @workgroup_size(1) fn main() { slots[0].v = vec4f(params.p0); atomicAdd(&counts[0], params.n); }\n",
    ));
    let wgsl = &program.compose().expect("links")[0];
    assert!(wgsl.contains(".p0"), "{wgsl}");
    naga::front::wgsl::parse_str(wgsl).expect("valid WGSL");
}

#[test]
fn the_path_tracer_s_program_links_to_valid_wgsl() {
    // Each method crate checks its own programs the same way (tests/gpu_structs.rs).
    render::path_tracer::PathTracer::program().check_links().unwrap_or_else(|e| panic!("{e}"));
    // And the check fails on a program that does not parse.
    let broken = Program::new(vec![]).entry(module("package::main", "fn main( {"));
    assert!(broken.check_links().is_err());
}
