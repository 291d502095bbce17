//! The shading library every method's passes are built on: its WGSL modules (scene geometry,
//! sampling, BSDFs, lights, the scene's @group(0) and the path integrator, without entry points) and the
//! run's cache of compiled passes, so that methods with equal passes share their pipelines,
//! each compiled for the features the scene has ([`SceneFeatures`]: kinds of light, textures,
//! the traversal stack its BVH needs).

use std::collections::HashMap;
use std::sync::{Arc, Mutex};

use crate::bvh::SceneGeometry;
use crate::compute::{self, BufferBinding};
use crate::error::RenderError;
use crate::frame::{CameraFrame, Frame};
use crate::gpu::Gpu;
use crate::gpu_struct::GpuStruct;
use crate::lights::GpuLight;
use crate::materials::GpuMaterial;
use crate::scene_features::SceneFeatures;
use crate::shader::{Module, Program};

/// Storage buffers a pass built on the library binds before its own: @group(0) (scene) and
/// @group(1) (geometry). Add the pass's own to check the adapter limit.
pub const LIBRARY_STORAGE_BUFFERS: u32 =
    crate::scene_group::STORAGE_BUFFERS + SceneGeometry::STORAGE_BUFFERS;

/// Texel tables (read-only storage textures) of the same two groups.
pub const LIBRARY_TEXEL_TABLES: u32 =
    crate::scene_group::TABLES.len() as u32 + SceneGeometry::TEXEL_TABLES;

/// A pipeline of the library, compiled for the features the scene has now. Fetch it with
/// [`Self::get`] each time a pass is recorded: [`PassLibrary::specialise`] replaces it when the
/// scene gains or loses a feature.
#[derive(Clone, Debug)]
pub struct LibraryPipeline(Arc<Mutex<wgpu::ComputePipeline>>);

impl LibraryPipeline {
    pub fn get(&self) -> wgpu::ComputePipeline {
        self.0.lock().unwrap_or_else(|e| e.into_inner()).clone()
    }
}

/// The same pass (shared by the methods that built it), not merely equal code.
impl PartialEq for LibraryPipeline {
    fn eq(&self, other: &Self) -> bool {
        Arc::ptr_eq(&self.0, &other.0)
    }
}

type Compile = Box<
    dyn Fn(
            &Gpu,
            [&wgpu::BindGroupLayout; 2],
            SceneFeatures,
        ) -> Result<Vec<wgpu::ComputePipeline>, RenderError>
        + Send,
>;

/// One pass built on the library: its own group's layout, its pipelines as the methods hold
/// them, and how to compile them for other features.
struct Pass {
    layout: wgpu::BindGroupLayout,
    pipelines: Vec<LibraryPipeline>,
    compile: Compile,
    /// Pipelines compiled so far, by features: a scene whose light comes back reuses them.
    variants: HashMap<SceneFeatures, Vec<wgpu::ComputePipeline>>,
}

struct State {
    features: SceneFeatures,
    /// Passes built so far, by (pass, source, own group, entry points).
    passes: HashMap<u64, Pass>,
}

pub struct PassLibrary {
    state: Mutex<State>,
}

impl PassLibrary {
    /// A library whose passes are compiled for `features`, the scene's.
    pub fn new(features: SceneFeatures) -> Self {
        Self { state: Mutex::new(State { features, passes: HashMap::new() }) }
    }

    /// The features the passes are compiled for.
    pub fn features(&self) -> SceneFeatures {
        self.state.lock().unwrap_or_else(|e| e.into_inner()).features
    }

    /// Compiles every pass built so far for `features` (or takes an earlier compilation) and
    /// swaps the pipelines the methods hold; later passes are built for `features`. Call when
    /// the scene's features change; a no-op otherwise. Every pass is compiled before any is
    /// swapped, so a failed compilation leaves all of them as they were.
    pub fn specialise(
        &self,
        gpu: &Gpu,
        groups: [&wgpu::BindGroupLayout; 2],
        features: SceneFeatures,
    ) -> Result<(), RenderError> {
        let mut state = self.state.lock().unwrap_or_else(|e| e.into_inner());
        if state.features == features {
            return Ok(());
        }
        for pass in state.passes.values_mut() {
            if !pass.variants.contains_key(&features) {
                let compiled = (pass.compile)(gpu, groups, features)?;
                pass.variants.insert(features, compiled);
            }
        }
        for pass in state.passes.values() {
            for (held, new) in pass.pipelines.iter().zip(&pass.variants[&features]) {
                *held.0.lock().unwrap_or_else(|e| e.into_inner()) = new.clone();
            }
        }
        state.features = features;
        Ok(())
    }

    /// The library's modules, each after those it imports: the scene's structs and its
    /// @group(0) (generated), the geometry's modules (first the scene's features, all of them:
    /// [`Self::pass`] compiles for the scene's own), its @group(1) and traversal, the kernel
    /// opening (`package::kernel`), sampling, BSDFs, lights, the scene's shading helpers and the
    /// path integrator. A pass's program starts with them.
    pub fn modules() -> &'static [Module] {
        static MODULES: std::sync::OnceLock<Vec<Module>> = std::sync::OnceLock::new();
        MODULES.get_or_init(|| {
            let types = Module::generated(
                "package::scene_types",
                &[CameraFrame::WGSL, Frame::WGSL, GpuMaterial::WGSL, GpuLight::WGSL],
            );
            let bindings = crate::texel_table::group_module(
                "package::scene_bindings",
                0,
                &crate::scene_group::GROUP,
                &crate::scene_group::TABLES,
                &[&types],
            );
            let mut modules = vec![types, bindings];
            modules.extend(SceneGeometry::modules());
            modules.extend([
                crate::wgsl_file!("kernel.wgsl"),
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

    /// One of the library's modules by its path (`package::pt_sampling`), for a pass that
    /// imports it without the rest of the library.
    pub fn module(path: &str) -> Module {
        Self::modules()
            .iter()
            .find(|m| m.path == path)
            .cloned()
            .unwrap_or_else(|| panic!("the pass library has no module {path}"))
    }

    /// A program on the library: its modules, then `own` (the pass's structs, bindings and
    /// files it imports), with the pass's entry-point files.
    pub fn program(
        own: impl IntoIterator<Item = Module>,
        entry_files: impl IntoIterator<Item = Module>,
    ) -> Program {
        let mut program = Program::new(Self::modules().to_vec()).with(own);
        program.entry_files.extend(entry_files);
        program
    }

    /// Refuses a pass whose own group `own`, with the library's groups, binds more storage
    /// buffers, or the library more storage textures, than the adapter allows per stage.
    pub fn check_storage_bindings(
        gpu: &Gpu,
        pass: &str,
        own: &[BufferBinding],
    ) -> Result<(), RenderError> {
        let needed = LIBRARY_STORAGE_BUFFERS + compute::storage_buffers(own);
        let limit = gpu.limits.max_storage_buffers_per_shader_stage;
        if needed > limit {
            return Err(crate::gpu::GpuError::OverLimit {
                what: format!("storage buffers of pass '{pass}'"),
                requested: needed as u64,
                limit: limit as u64,
                adapter: gpu.summary.name.clone(),
            }
            .into());
        }
        let limit = gpu.limits.max_storage_textures_per_shader_stage;
        if LIBRARY_TEXEL_TABLES > limit {
            return Err(crate::gpu::GpuError::OverLimit {
                what: format!("storage textures (texel tables) of pass '{pass}'"),
                requested: LIBRARY_TEXEL_TABLES as u64,
                limit: limit as u64,
                adapter: gpu.summary.name.clone(),
            }
            .into());
        }
        Ok(())
    }

    /// The layout of a pass's own @group(2) and the pipelines of `entries` in `program` (a
    /// [`Self::program`] whose own modules include `compute::group_module(.., 2, own, ..)`, so a
    /// pass states its buffers once), compiled for the library's scene features against the
    /// scene's `groups` ([`crate::scene_gpu::SceneGpu::library_groups`]). Refuses a pass
    /// with more storage buffers or textures than the adapter binds. Equal passes are compiled once per run.
    pub fn pass<const N: usize>(
        &self,
        gpu: &Gpu,
        groups: [&wgpu::BindGroupLayout; 2],
        pass: &str,
        program: &Program,
        own: &[BufferBinding],
        entries: [&str; N],
    ) -> Result<(wgpu::BindGroupLayout, [LibraryPipeline; N]), RenderError> {
        Self::check_storage_bindings(gpu, pass, own)?;
        // Methods of one run share the pipelines of equal passes (three sample caches, two hash
        // caches): fewer compiled shaders, and on llvmpipe a working set that stays inside its
        // shader-variant cache, whose evictions cost seconds of recompilation per frame.
        let key = {
            use std::hash::{Hash, Hasher};
            let mut h = std::collections::hash_map::DefaultHasher::new();
            (pass, program, format!("{own:?}"), entries.as_slice()).hash(&mut h);
            h.finish()
        };
        let mut state = self.state.lock().unwrap_or_else(|e| e.into_inner());
        if let Some(built) = state.passes.get(&key)
            && let Ok(pipelines) = <[LibraryPipeline; N]>::try_from(built.pipelines.clone())
        {
            return Ok((built.layout.clone(), pipelines));
        }
        let layout = compute::binding_layout(gpu, pass, own);
        let compile: Compile = {
            let (name, program, layout, entries) =
                (pass.to_string(), program.clone(), layout.clone(), entries.map(String::from));
            Box::new(move |gpu: &Gpu, [scene, geometry]: [&wgpu::BindGroupLayout; 2], features| {
                let specialised = program.replacing(&features.module());
                let groups = [scene, geometry, &layout];
                Ok(compute::pipelines(
                    gpu,
                    &name,
                    &specialised,
                    &groups,
                    entries.each_ref().map(String::as_str),
                )?
                .to_vec())
            })
        };
        let features = state.features;
        let compiled = compile(gpu, groups, features)?;
        let pipelines: Vec<LibraryPipeline> =
            compiled.iter().map(|p| LibraryPipeline(Arc::new(Mutex::new(p.clone())))).collect();
        let held = <[LibraryPipeline; N]>::try_from(pipelines.clone())
            .unwrap_or_else(|_| unreachable!("one pipeline per entry point"));
        state.passes.insert(
            key,
            Pass {
                layout: layout.clone(),
                pipelines,
                compile,
                variants: HashMap::from([(features, compiled)]),
            },
        );
        Ok((layout, held))
    }
}
