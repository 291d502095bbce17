//! The scene as every pass built on the shading library binds it: @group(0) holds the `Frame`
//! parameters (camera, previous camera, lights, seed, spp, depth), the texture atlas, and the
//! materials and the light table as texel tables (read per hit at per-ray addresses:
//! `crate::texel_table` says why), all read only; @group(1) is the geometry (BLAS, TLAS,
//! instances). One per run, updated once per frame; methods read it and never write it.

use crate::bvh::SceneGeometry;
use crate::compute::{self, BufferBinding};
use crate::error::RenderError;
use crate::frame::{CameraBasis, Frame, FrameParams};
use crate::gpu::Gpu;
use crate::lights::{LightTable, build_light_table};
use crate::materials::{GpuMaterial, NO_TEXTURE, pack_materials};
use crate::scene::{Camera, SceneChanges, SceneDesc};
use crate::scene_features::SceneFeatures;
use crate::texel_table::TexelTable;
use glam::Vec3;
use wgpu::util::DeviceExt;

/// @group(0)'s buffers: frame uniform, texels (declared into the library's WGSL).
pub const GROUP: [BufferBinding; 2] =
    [BufferBinding::read("frame", "Frame"), BufferBinding::read("texels", "array<u32>")];
/// Its texel tables after the buffers: `GpuMaterial`s (3 texels) and `GpuLight`s (4 texels),
/// read through scene_tables.wgsl.
pub const TABLES: [&str; 2] = ["material_table", "light_table"];
const MATERIAL_TEXELS: u32 = 3;
const LIGHT_TEXELS: u32 = 4;
const _: () = assert!(size_of::<crate::materials::GpuMaterial>() == 16 * MATERIAL_TEXELS as usize);
const _: () = assert!(size_of::<crate::lights::GpuLight>() == 16 * LIGHT_TEXELS as usize);

/// Storage buffers of @group(0).
pub const STORAGE_BUFFERS: u32 = compute::storage_buffers(&GROUP);

/// Image size and path depth: what every pass's frame uniform carries besides the scene (the
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

pub struct SceneBindings {
    settings: PathTracerSettings,
    geometry: SceneGeometry,
    layout: wgpu::BindGroupLayout,
    bind_group: wgpu::BindGroup,
    frame_buffer: wgpu::Buffer,
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
    /// The most traversal-stack entries the scene's BVH has needed so far: the stack never
    /// shrinks within a run, so that a TLAS whose depth moves up and down under animation costs
    /// a compilation only when it grows past its deepest.
    traversal_stack: u32,
}

impl SceneBindings {
    pub fn new(
        gpu: &Gpu,
        scene: &SceneDesc,
        settings: PathTracerSettings,
    ) -> Result<Self, RenderError> {
        let geometry = SceneGeometry::new(gpu, scene)?;
        let (materials_cpu, texels) = pack_materials(scene)?;
        let light_table = build_light_table(scene)?;
        let device = &gpu.device;
        let storage = |label: &str, contents: &[u8]| -> Result<wgpu::Buffer, RenderError> {
            gpu.check_buffer_size(label, contents.len() as u64)?;
            Ok(device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
                label: Some(label),
                contents,
                usage: wgpu::BufferUsages::STORAGE | wgpu::BufferUsages::COPY_DST,
            }))
        };
        let materials = TexelTable::new(
            gpu,
            "materials",
            MATERIAL_TEXELS,
            bytemuck::cast_slice(&materials_cpu),
            0,
        )?;
        let texels = storage("base-colour texels", bytemuck::cast_slice(&texels))?;
        let lights = TexelTable::new(
            gpu,
            "lights",
            LIGHT_TEXELS,
            bytemuck::cast_slice(&light_table.lights),
            0,
        )?;
        let frame_buffer = device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("frame uniform"),
            size: size_of::<Frame>() as u64,
            usage: wgpu::BufferUsages::STORAGE | wgpu::BufferUsages::COPY_DST,
            mapped_at_creation: false,
        });
        let layout = crate::texel_table::group_layout(gpu, "scene", &GROUP, TABLES.len());
        let bind_group = bind_group(gpu, &layout, &frame_buffer, &texels, &materials, &lights);
        let geometry_stack = geometry.stack_entries();
        Ok(Self {
            settings,
            geometry,
            layout,
            bind_group,
            frame_buffer,
            materials,
            texels,
            lights,
            light_table,
            camera: scene.camera,
            previous_camera: scene.camera,
            environment: scene.environment,
            textured: textured(&materials_cpu),
            traversal_stack: geometry_stack,
        })
    }

    /// Uploads what `changes` names: materials and texels when materials changed, the light
    /// table when lights, instances (emissive triangles follow them) or materials changed.
    /// Instance transforms and the camera are taken every frame: they become the previous ones
    /// of motion vectors.
    pub fn update_changed(
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
        let mut rebind = false;
        let mut uploads: Vec<(&mut wgpu::Buffer, &str, &[u8])> = Vec::new();
        if let Some((materials, texels)) = &materials {
            rebind |= self.materials.replace(gpu, bytemuck::cast_slice(materials))?;
            uploads.push((&mut self.texels, "base-colour texels", bytemuck::cast_slice(texels)));
            self.textured = textured(materials);
        }
        if let Some(table) = &light_table {
            rebind |= self.lights.replace(gpu, bytemuck::cast_slice(&table.lights))?;
        }
        for (buffer, label, bytes) in uploads {
            if buffer.size() == bytes.len() as u64 {
                gpu.queue.write_buffer(buffer, 0, bytes);
            } else {
                gpu.check_buffer_size(label, bytes.len() as u64)?;
                *buffer = gpu.device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
                    label: Some(label),
                    contents: bytes,
                    usage: wgpu::BufferUsages::STORAGE | wgpu::BufferUsages::COPY_DST,
                });
                rebind = true;
            }
        }
        if rebind {
            self.bind_group = bind_group(
                gpu,
                &self.layout,
                &self.frame_buffer,
                &self.texels,
                &self.materials,
                &self.lights,
            );
        }
        if let Some(table) = light_table {
            self.light_table = table;
        }
        self.previous_camera = self.camera;
        self.camera = scene.camera;
        self.environment = scene.environment;
        Ok(())
    }

    /// Writes the frame uniform for a pass (camera, previous camera, lights, `spp` and the first
    /// sample index, seed, frame, max depth), as the path tracer's own passes see it.
    pub fn prepare_frame(&self, gpu: &Gpu, spp: u32, first_sample: u32, seed: u64, frame: u32) {
        self.write_frame(gpu, spp, first_sample, seed, frame, false);
    }

    /// [`Self::prepare_frame`] with `accumulate`: the path tracer's later batches add to the
    /// radiance sum instead of replacing it.
    pub fn write_frame(
        &self,
        gpu: &Gpu,
        spp: u32,
        first_sample: u32,
        seed: u64,
        frame: u32,
        accumulate: bool,
    ) {
        let (w, h) = (self.settings.width, self.settings.height);
        let params = FrameParams {
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
        };
        gpu.queue.write_buffer(&self.frame_buffer, 0, bytemuck::bytes_of(&params.gpu()));
    }

    /// The scene's features as last uploaded: what the library's passes are compiled for
    /// ([`crate::pass_library::PassLibrary::specialise`]).
    pub fn features(&self) -> SceneFeatures {
        SceneFeatures {
            analytic_lights: self.light_table.analytic > 0,
            emitters: self.light_table.emitters > 0,
            environment: self.environment.max_element() > 0.0,
            textures: self.textured,
            traversal_stack: SceneFeatures::stack_for(self.traversal_stack),
        }
    }

    /// Point, spot and directional lights as last uploaded (`frame.analytic_lights`).
    pub fn analytic_lights(&self) -> u32 {
        self.light_table.analytic
    }

    /// @group(0). It changes when an update had to grow a buffer: fetch it every frame.
    pub fn bind_group(&self) -> &wgpu::BindGroup {
        &self.bind_group
    }

    pub fn layout(&self) -> &wgpu::BindGroupLayout {
        &self.layout
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

/// Whether a material's base colour is read from a texture (base_color_at in pt_scene.wgsl).
fn textured(materials: &[GpuMaterial]) -> bool {
    materials
        .iter()
        .any(|m| m.texture_offset != NO_TEXTURE && m.texture_width > 0 && m.texture_height > 0)
}

/// @group(0): [`GROUP`]'s buffers, then [`TABLES`].
fn bind_group(
    gpu: &Gpu,
    layout: &wgpu::BindGroupLayout,
    frame: &wgpu::Buffer,
    texels: &wgpu::Buffer,
    materials: &TexelTable,
    lights: &TexelTable,
) -> wgpu::BindGroup {
    crate::texel_table::group(gpu, "scene", layout, &[frame, texels], &[materials, lights])
}
