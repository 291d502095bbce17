//! GPU structs defined once for Rust and WGSL. [`gpu_struct!`](crate::gpu_struct) declares a
//! `#[repr(C)]` Pod struct with named fields and, from the same field list, its WGSL
//! declaration ([`GpuStruct::WGSL`]); shaders import it from a generated module
//! (`shader::Module::generated`) instead of declaring the struct themselves. `render/tests/gpu_structs.rs` checks with naga that every
//! field sits at the same byte offset on both sides (WGSL's alignment rules differ from Rust's,
//! e.g. for `vec3f`), so a layout mismatch fails a test instead of corrupting a pass.

/// A struct shared by Rust and WGSL.
pub trait GpuStruct: bytemuck::Pod {
    /// The WGSL declaration, `struct NAME { field: type, ... }`.
    const WGSL: &'static str;
    /// Each field's name and byte offset in the Rust struct, in declaration order.
    fn offsets() -> Vec<(&'static str, usize)>;
}

/// The differences between `T`'s Rust layout and its WGSL declaration's, as naga lays it out
/// (`deps`: the declarations it uses). Empty when every field has the same name, byte offset and
/// the struct the same size on both sides.
pub fn layout_mismatches<T: GpuStruct>(deps: &str) -> Vec<String> {
    let source = format!("{deps}\n{}", T::WGSL);
    let module = match naga::front::wgsl::parse_str(&source) {
        Ok(m) => m,
        Err(e) => return vec![e.emit_to_string(&source)],
    };
    let mut layouter = naga::proc::Layouter::default();
    if let Err(e) = layouter.update(module.to_ctx()) {
        return vec![format!("layout: {e}")];
    }
    let name = T::WGSL.split_whitespace().nth(1).unwrap_or("?");
    let Some((_, ty)) = module.types.iter().find(|(_, t)| t.name.as_deref() == Some(name)) else {
        return vec![format!("{name} not declared")];
    };
    let naga::TypeInner::Struct { members, span } = &ty.inner else {
        return vec![format!("{name} is not a struct")];
    };
    let rust = T::offsets();
    let mut out = Vec::new();
    if members.len() != rust.len() {
        out.push(format!("{name}: {} WGSL fields, {} Rust fields", members.len(), rust.len()));
    }
    for (m, (field, offset)) in members.iter().zip(&rust) {
        if m.name.as_deref() != Some(*field) || m.offset as usize != *offset {
            out.push(format!(
                "{name}.{field}: Rust offset {offset}, WGSL {:?} at {}",
                m.name, m.offset
            ));
        }
    }
    if *span as usize != size_of::<T>() {
        out.push(format!("{name}: Rust size {}, WGSL {span}", size_of::<T>()));
    }
    out
}

/// `gpu_struct! { /// doc  pub struct Name { /// doc  pub field: [f32; 3] => "vec3f", ... } }`
#[macro_export]
macro_rules! gpu_struct {
    ($(#[$m:meta])* $vis:vis struct $name:ident { $($(#[$fm:meta])* $fvis:vis $field:ident : $ty:ty => $wgsl:literal),* $(,)? }) => {
        $(#[$m])*
        #[repr(C)]
        #[derive(Clone, Copy, Debug, bytemuck::Pod, bytemuck::Zeroable)]
        $vis struct $name {
            $($(#[$fm])* $fvis $field: $ty),*
        }

        impl $crate::gpu_struct::GpuStruct for $name {
            const WGSL: &'static str = concat!("struct ", stringify!($name), " {\n", $("    ", stringify!($field), ": ", $wgsl, ",\n",)* "}\n");
            fn offsets() -> Vec<(&'static str, usize)> {
                vec![$((stringify!($field), core::mem::offset_of!($name, $field))),*]
            }
        }
    };
}
