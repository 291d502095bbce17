//! The shading library every method's passes are built on: its WGSL modules (scene geometry,
//! sampling, BSDFs, lights, the scene's @group(0) and the path integrator, without entry points) and the
//! run's cache of compiled passes, so that methods with equal passes share their pipelines.

use std::collections::HashMap;
use std::sync::Mutex;

use crate::bvh::SceneGeometry;
use crate::compute::{self, BufferBinding};
use crate::frame::{CameraFrame, Frame};
use crate::gpu_struct::GpuStruct;
use crate::lights::GpuLight;
use crate::materials::GpuMaterial;
use crate::error::RenderError;
use crate::gpu::Gpu;
use crate::scene_bindings::SceneBindings;
use crate::shader::{Module, Program};

/// Storage buffers a pass built on the library binds before its own: @group(0) (scene) and
/// @group(1) (geometry). Add the pass's own to check the adapter limit.
pub const LIBRARY_STORAGE_BUFFERS: u32 = crate::scene_bindings::STORAGE_BUFFERS + SceneGeometry::STORAGE_BUFFERS;

type Compiled = (wgpu::BindGroupLayout, Vec<wgpu::ComputePipeline>);

#[derive(Default)]
pub struct PassLibrary {
    /// Passes built so far, by (pass, source, own group, entry points).
    compiled: Mutex<HashMap<u64, Compiled>>,
}

impl PassLibrary {
    /// The library's modules, each after those it imports: the scene's structs and its
    /// @group(0) (generated), the geometry's @group(1) and traversal, sampling, BSDFs, lights,
    /// the scene's shading helpers and the path integrator. A pass's program starts with them.
    pub fn modules() -> &'static [Module] {
        static MODULES: std::sync::OnceLock<Vec<Module>> = std::sync::OnceLock::new();
        MODULES.get_or_init(|| {
            let types = Module::generated("package::scene_types", &[CameraFrame::WGSL, Frame::WGSL, GpuMaterial::WGSL, GpuLight::WGSL]);
            let bindings = crate::texel_table::group_module("package::scene_bindings", 0, &crate::scene_bindings::GROUP, &crate::scene_bindings::TABLES, &[&types]);
            let mut modules = vec![types, bindings];
            modules.extend(SceneGeometry::modules());
            modules.extend([
                crate::wgsl_file!("scene_tables.wgsl"),
                crate::wgsl_file!("pt_sampling.wgsl"),
                crate::wgsl_file!("pt_bsdf.wgsl"),
                crate::wgsl_file!("pt_lights.wgsl"),
                crate::wgsl_file!("pt_scene.wgsl"),
                crate::wgsl_file!("pt_integrator.wgsl"),
            ]);
            modules
        })
    }

    /// A program on the library: its modules, then `own` (the pass's structs, bindings and
    /// files it imports), with the pass's entry-point files.
    pub fn program(own: impl IntoIterator<Item = Module>, entry_files: impl IntoIterator<Item = Module>) -> Program {
        let mut program = Program::new(Self::modules().to_vec()).with(own);
        program.entry_files.extend(entry_files);
        program
    }

    /// The layout of a pass's own @group(2) and the pipelines of `entries` in `program` (a
    /// [`Self::program`] whose own modules include `compute::group_module(.., 2, own, ..)`, so a
    /// pass states its buffers once). Refuses a pass with more storage buffers than the adapter
    /// binds. Equal passes are compiled once per run.
    pub fn pass<const N: usize>(
        &self,
        gpu: &Gpu,
        scene: &SceneBindings,
        pass: &str,
        program: &Program,
        own: &[BufferBinding],
        entries: [&str; N],
    ) -> Result<(wgpu::BindGroupLayout, [wgpu::ComputePipeline; N]), RenderError> {
        let needed = LIBRARY_STORAGE_BUFFERS + compute::storage_buffers(own);
        let limit = gpu.limits.max_storage_buffers_per_shader_stage;
        if needed > limit {
            return Err(crate::gpu::GpuError::OverLimit { what: format!("storage buffers of pass '{pass}'"), requested: needed as u64, limit: limit as u64, adapter: gpu.summary.name.clone() }.into());
        }
        // Methods of one run share the pipelines of equal passes (three sample caches, two hash
        // caches): fewer compiled shaders, and on llvmpipe a working set that stays inside its
        // shader-variant cache, whose evictions cost seconds of recompilation per frame.
        let key = {
            use std::hash::{Hash, Hasher};
            let mut h = std::collections::hash_map::DefaultHasher::new();
            (pass, program, format!("{own:?}"), entries.as_slice()).hash(&mut h);
            h.finish()
        };
        let mut compiled = self.compiled.lock().unwrap_or_else(|e| e.into_inner());
        if let Some((layout, pipelines)) = compiled.get(&key)
            && let Ok(pipelines) = <[wgpu::ComputePipeline; N]>::try_from(pipelines.clone())
        {
            return Ok((layout.clone(), pipelines));
        }
        let layout = compute::binding_layout(gpu, pass, own);
        let pipelines = compute::pipelines(gpu, pass, program, &[scene.layout(), scene.geometry().bind_group_layout(), &layout], entries)?;
        compiled.insert(key, (layout.clone(), pipelines.to_vec()));
        Ok((layout, pipelines))
    }
}
