//! GPU structs defined once for Rust and WGSL. [`gpu_struct!`](crate::gpu_struct) declares a
//! `#[repr(C)]` Pod struct with named fields and, from the same field list, its WGSL
//! declaration ([`GpuStruct::WGSL`]); shaders get the declaration prepended instead of
//! declaring the struct themselves. `render/tests/gpu_structs.rs` checks with naga that every
//! field sits at the same byte offset on both sides (WGSL's alignment rules differ from Rust's,
//! e.g. for `vec3f`), so a layout mismatch fails a test instead of corrupting a pass.

/// A struct shared by Rust and WGSL.
pub trait GpuStruct: bytemuck::Pod {
    /// The WGSL declaration, `struct NAME { field: type, ... }`.
    const WGSL: &'static str;
    /// Each field's name and byte offset in the Rust struct, in declaration order.
    fn offsets() -> Vec<(&'static str, usize)>;
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
