//! The scene on the GPU, as every pass built on the shading library reads it: the geometry's
//! @group(1) (BLAS, TLAS, instances), the texture atlas, the materials and the light table as
//! texel tables (read per hit at per-ray addresses: `crate::texel_table` says why), the camera,
//! the scene's features and the pass library compiled for them. One per run, updated once per
//! frame; methods read it and never write it. Each method binds the shared tables at @group(0)
//! next to its own `Frame` parameters (camera, previous camera, lights, seed, spp, depth):
//! [`crate::frame_bindings::FrameBindings`], which rebuilds its group when [`SceneGpu::generation`]
//! says the tables were reallocated.

use crate::bvh::SceneGeometry;
use crate::compute::BufferBinding;
use crate::error::RenderError;
use crate::frame::{CameraBasis, FrameParams};
use crate::gpu::Gpu;
use crate::lights::{LightTable, build_light_table};
use crate::materials::{GpuMaterial, NO_TEXTURE, pack_materials};
use crate::pass_library::{LibraryPipeline, PassLibrary};
use crate::scene::{Camera, SceneChanges, SceneDesc};
use crate::scene_features::SceneFeatures;
use crate::scene_group::{GROUP, LIGHT_TEXELS, MATERIAL_TEXELS, TABLES};
use crate::shader::Program;
use crate::texel_table::TexelTable;
use glam::Vec3;

/// Image size and path depth: what every pass's frame parameters carry besides the scene (the
/// path tracer's settings; `render::path_tracer` re-exports it).
#[derive(Clone, Copy, Debug, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
pub struct PathTracerSettings {
    pub width: u32,
    pub height: u32,
    /// Maximum number of scattering events: 1 = direct lighting only.
    pub max_depth: u32,
    /// Russian roulette applies to bounces from this depth on (1 = after the first bounce).
    pub rr_start_depth: u32,
}

pub struct SceneGpu {
    settings: PathTracerSettings,
    geometry: SceneGeometry,
    /// Layout of @group(0): a method's frame parameters, then the tables below.
    layout: wgpu::BindGroupLayout,
    /// Bumped whenever an update reallocates the texels or a texel table: every method's
    /// @group(0) made before then binds the old ones.
    generation: u64,
    library: PassLibrary,
    texels: wgpu::Buffer,
    materials: TexelTable,
    lights: TexelTable,
    light_table: LightTable,
    camera: Camera,
    /// Camera before the last `update` (motion vectors), like the instances' previous
    /// transforms; the current camera before the first update.
    previous_camera: Camera,
    environment: Vec3,
    /// Some material has a base-colour texture.
    textured: bool,
    /// Some material has a specular lobe.
    specular: bool,
    /// The most traversal-stack entries the scene's BVH has needed so far: the stack never
    /// shrinks within a run, so that a TLAS whose depth moves up and down under animation costs
    /// a compilation only when it grows past its deepest.
    traversal_stack: u32,
}

impl SceneGpu {
    /// The scene uploaded, and a pass library for its features. Refuses settings no method can
    /// render with (no bounce, an image larger than the adapter's textures).
    pub fn new(
        gpu: &Gpu,
        scene: &SceneDesc,
        settings: PathTracerSettings,
    ) -> Result<Self, RenderError> {
        if settings.max_depth == 0 {
            return Err(RenderError::Settings(
                "max_depth must be at least 1 (1 = direct lighting)".into(),
            ));
        }
        gpu.check_resolution(settings.width, settings.height, 0)?;
        let geometry = SceneGeometry::new(gpu, scene)?;
        let (materials_cpu, texels) = pack_materials(scene)?;
        let light_table = build_light_table(scene)?;
        let materials = TexelTable::new(
            gpu,
            "materials",
            MATERIAL_TEXELS,
            bytemuck::cast_slice(&materials_cpu),
            0,
        )?;
        let texels = gpu.checked_buffer_init(
            "base-colour texels",
            bytemuck::cast_slice(&texels),
            wgpu::BufferUsages::STORAGE | wgpu::BufferUsages::COPY_DST,
        )?;
        let lights = TexelTable::new(
            gpu,
            "lights",
            LIGHT_TEXELS,
            bytemuck::cast_slice(&light_table.lights),
            0,
        )?;
        let layout = crate::texel_table::group_layout(gpu, "scene", &GROUP, TABLES.len());
        let traversal_stack = geometry.stack_entries();
        let textured = textured(&materials_cpu);
        let specular = specular(&materials_cpu);
        let features =
            scene_features(&light_table, scene.environment, textured, specular, traversal_stack);
        Ok(Self {
            settings,
            geometry,
            layout,
            generation: 0,
            library: PassLibrary::new(features),
            materials,
            texels,
            lights,
            light_table,
            camera: scene.camera,
            previous_camera: scene.camera,
            environment: scene.environment,
            textured,
            specular,
            traversal_stack,
        })
    }

    /// [`Self::update_changed`] with everything changed, panicking on an inconsistent scene.
    /// Call once per simulated frame: the camera and instance transforms it replaces become the
    /// previous ones of motion vectors.
    pub fn update(&mut self, gpu: &Gpu, scene: &SceneDesc) {
        if let Err(e) = self.try_update(gpu, scene) {
            panic!("SceneGpu::update: {e}");
        }
    }

    /// [`Self::update`] that reports an inconsistent scene instead of panicking.
    pub fn try_update(&mut self, gpu: &Gpu, scene: &SceneDesc) -> Result<(), RenderError> {
        self.update_changed(gpu, scene, SceneChanges::ALL)
    }

    /// Uploads what `changes` names: materials and texels when materials changed, the light
    /// table when lights, instances (emissive triangles follow them) or materials changed.
    /// Instance transforms and the camera are taken every frame: they become the previous ones
    /// of motion vectors. Meshes are fixed at `new`. When the scene gains or loses a feature (a
    /// kind of light, textures), every pass of the library is compiled again for its features
    /// ([`PassLibrary::specialise`]).
    pub fn update_changed(
        &mut self,
        gpu: &Gpu,
        scene: &SceneDesc,
        changes: SceneChanges,
    ) -> Result<(), RenderError> {
        self.upload_changed(gpu, scene, changes)?;
        self.library.specialise(gpu, self.library_groups(), self.features())
    }

    fn upload_changed(
        &mut self,
        gpu: &Gpu,
        scene: &SceneDesc,
        changes: SceneChanges,
    ) -> Result<(), RenderError> {
        let materials =
            (changes.materials || changes.geometry).then(|| pack_materials(scene)).transpose()?;
        let light_table =
            (changes.lights || changes.instances || changes.materials || changes.geometry)
                .then(|| build_light_table(scene))
                .transpose()?;
        self.geometry.try_update_instances(gpu, &scene.instances)?;
        self.traversal_stack = self.traversal_stack.max(self.geometry.stack_entries());
        let mut reallocated = false;
        let mut uploads: Vec<(&mut wgpu::Buffer, &str, &[u8])> = Vec::new();
        if let Some((materials, texels)) = &materials {
            reallocated |= self.materials.replace(gpu, bytemuck::cast_slice(materials))?;
            uploads.push((&mut self.texels, "base-colour texels", bytemuck::cast_slice(texels)));
            self.textured = textured(materials);
            self.specular = specular(materials);
        }
        if let Some(table) = &light_table {
            reallocated |= self.lights.replace(gpu, bytemuck::cast_slice(&table.lights))?;
        }
        for (buffer, label, bytes) in uploads {
            if buffer.size() == bytes.len() as u64 {
                gpu.queue.write_buffer(buffer, 0, bytes);
            } else {
                *buffer = gpu.checked_buffer_init(
                    label,
                    bytes,
                    wgpu::BufferUsages::STORAGE | wgpu::BufferUsages::COPY_DST,
                )?;
                reallocated = true;
            }
        }
        if reallocated {
            self.generation += 1;
        }
        if let Some(table) = light_table {
            self.light_table = table;
        }
        self.previous_camera = self.camera;
        self.camera = scene.camera;
        self.environment = scene.environment;
        Ok(())
    }

    /// A pass's frame parameters (camera, previous camera, lights, `spp` and the first sample
    /// index, seed, frame, max depth) on the scene as last uploaded; `accumulate`: the path
    /// tracer's later batches add to the radiance sum instead of replacing it.
    pub(crate) fn frame_params(
        &self,
        spp: u32,
        first_sample: u32,
        seed: u64,
        frame: u32,
        accumulate: bool,
    ) -> FrameParams {
        let (w, h) = (self.settings.width, self.settings.height);
        FrameParams {
            camera: CameraBasis::new(&self.camera, w, h),
            previous_camera: CameraBasis::new(&self.previous_camera, w, h),
            environment: self.environment,
            emitter_weight: self.light_table.emitter_weight,
            width: w,
            height: h,
            spp,
            first_sample,
            seed,
            frame,
            max_depth: self.settings.max_depth,
            rr_start_depth: self.settings.rr_start_depth,
            analytic_lights: self.light_table.analytic,
            emitters: self.light_table.emitters,
            accumulate,
        }
    }

    /// @group(0) over `frame` (a method's frame parameters) and the tables as they are now.
    pub(crate) fn bind_group(&self, gpu: &Gpu, frame: &wgpu::Buffer) -> wgpu::BindGroup {
        crate::texel_table::group(
            gpu,
            "scene",
            &self.layout,
            &[frame, &self.texels],
            &[&self.materials, &self.lights],
        )
    }

    /// Counts the updates that reallocated a table: a method's @group(0) made at another
    /// generation binds tables the scene no longer uses.
    pub fn generation(&self) -> u64 {
        self.generation
    }

    /// The scene's features as last uploaded: what the library's passes are compiled for
    /// ([`PassLibrary::specialise`]).
    pub fn features(&self) -> SceneFeatures {
        scene_features(
            &self.light_table,
            self.environment,
            self.textured,
            self.specular,
            self.traversal_stack,
        )
    }

    /// Point, spot and directional lights as last uploaded (`frame.analytic_lights`).
    pub fn analytic_lights(&self) -> u32 {
        self.light_table.analytic
    }

    /// The pass library: the shading library's source and the run's shared pipelines.
    pub fn library(&self) -> &PassLibrary {
        &self.library
    }

    /// [`PassLibrary::pass`] on this scene.
    pub fn library_pass<const N: usize>(
        &self,
        gpu: &Gpu,
        pass: &str,
        program: &Program,
        own: &[BufferBinding],
        entries: [&str; N],
    ) -> Result<(wgpu::BindGroupLayout, [LibraryPipeline; N]), RenderError> {
        self.library.pass(gpu, self.library_groups(), pass, program, own, entries)
    }

    /// Layout of @group(0) (a method's frame parameters and the scene's tables).
    pub fn layout(&self) -> &wgpu::BindGroupLayout {
        &self.layout
    }

    /// The layouts of @group(0) and @group(1), which every pass of the library binds before its
    /// own (what [`PassLibrary`] compiles its passes against).
    pub fn library_groups(&self) -> [&wgpu::BindGroupLayout; 2] {
        [&self.layout, self.geometry.bind_group_layout()]
    }

    /// @group(1) and the scene's bounds.
    pub fn geometry(&self) -> &SceneGeometry {
        &self.geometry
    }

    /// The camera of the current frame (after the last update).
    pub fn camera(&self) -> &Camera {
        &self.camera
    }

    pub fn settings(&self) -> PathTracerSettings {
        self.settings
    }
}

fn scene_features(
    lights: &LightTable,
    environment: Vec3,
    textured: bool,
    specular: bool,
    traversal_stack: u32,
) -> SceneFeatures {
    SceneFeatures {
        analytic_lights: lights.analytic > 0,
        emitters: lights.emitters > 0,
        environment: environment.max_element() > 0.0,
        textures: textured,
        specular,
        traversal_stack: SceneFeatures::stack_for(traversal_stack),
    }
}

/// Whether a material's base colour is read from a texture (base_color_at in pt_scene.wgsl).
fn textured(materials: &[GpuMaterial]) -> bool {
    materials
        .iter()
        .any(|m| m.texture_offset != NO_TEXTURE && m.texture_width > 0 && m.texture_height > 0)
}

/// Whether a material has a specular lobe: make_bsdf (pt_bsdf.wgsl) gives f0 = f90 = 0, a
/// Lambertian BSDF, exactly when metallic and the specular factor are at most 0 (NaN counts as a
/// lobe: such a material keeps the general code).
fn specular(materials: &[GpuMaterial]) -> bool {
    materials.iter().any(|m| !(m.metallic <= 0.0 && m.specular <= 0.0))
}
