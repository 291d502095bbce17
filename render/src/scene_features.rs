//! What kinds of light and surface a scene has (analytic lights, emissive triangles, a constant
//! environment, textured materials, materials with a specular lobe) and how deep its BVH is, as
//! the WGSL constants the library's passes are compiled with.
//!
//! Why: lavapipe runs a branch that no invocation takes under an empty mask instead of jumping
//! over it, so next-event estimation towards a kind of light the scene lacks costs a light sample
//! and a shadow ray's traversal per vertex all the same, and an untextured scene pays for four
//! texel loads per hit (docs/lab/render-speed.md), and a scene of Lambertian materials for the
//! Fresnel-coupled diffuse and GGX arithmetic of every BSDF evaluation, whose values are exactly
//! the Lambertian ones for it (pt_bsdf.wgsl). A pass compiled with the feature's constant `false`
//! has no such code. A GPU skips such branches anyway. No result changes: a light kind's
//! estimator draws no random numbers when the scene has none of it.
//!
//! The traversal stack is sized for the scene's BVH because lavapipe keeps an array indexed at
//! run time in per-invocation scratch memory, read and written one lane at a time. The stack is
//! instead indexed with selects over every entry (scene_geometry.wgsl), which keeps it in
//! registers and costs in proportion to its size.

use crate::bvh::TRAVERSAL_STACK_SIZE;
use crate::shader::Module;

/// Module path of the constants: `import package::scene_features::{HAS_EMITTERS, ...}`.
pub const MODULE: &str = "package::scene_features";

#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub struct SceneFeatures {
    /// Point, spot or directional lights (`frame.analytic_lights` > 0).
    pub analytic_lights: bool,
    /// Emissive triangles (`frame.emitters` > 0).
    pub emitters: bool,
    /// A non-black constant environment (`environment_pdf()` > 0).
    pub environment: bool,
    /// A material with a base-colour texture.
    pub textures: bool,
    /// A material with a specular lobe (metallic or KHR specular factor above 0); without one
    /// every BSDF is Lambertian.
    pub specular: bool,
    /// Entries of the traversal stack: what the scene's BVH can need ([`Self::stack_for`]).
    pub traversal_stack: u32,
}

impl SceneFeatures {
    /// Every feature: right for any scene. Programs are written with it; the pass library
    /// compiles its passes for the scene's own features.
    pub const ALL: Self = Self {
        analytic_lights: true,
        emitters: true,
        environment: true,
        textures: true,
        specular: true,
        traversal_stack: TRAVERSAL_STACK_SIZE,
    };

    /// The stack for a BVH that can need `entries`: exactly that (each entry costs a select per
    /// push and per pop), at most [`TRAVERSAL_STACK_SIZE`] (deeper scenes are refused when their
    /// BVH is built).
    pub fn stack_for(entries: u32) -> u32 {
        entries.clamp(1, TRAVERSAL_STACK_SIZE)
    }

    /// The constants as a module at [`MODULE`].
    pub fn module(self) -> Module {
        let constants = [
            ("HAS_ANALYTIC_LIGHTS", self.analytic_lights),
            ("HAS_EMITTERS", self.emitters),
            ("HAS_ENVIRONMENT", self.environment),
            ("HAS_TEXTURES", self.textures),
            ("HAS_SPECULAR", self.specular),
        ]
        .map(|(name, value)| format!("const {name}: bool = {value};"));
        let stack = format!("const TRAVERSAL_STACK_ENTRIES: u32 = {}u;", self.traversal_stack);
        Module::generated(MODULE, &[&constants.join("\n"), &stack])
    }
}
