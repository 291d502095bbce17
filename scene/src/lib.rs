//! The scene as the renderer sees it: plain data, no ECS.
//!
//! `sim` builds these from its world (glTF import, built-in scenes) and refreshes the dynamic
//! parts (instances, lights, camera, materials) every frame; `render` draws them. Its own crate so
//! that neither depends on the other.
//! Units: metres, radians; radiance in W/(sr m^2) on a linear RGB scale.

pub mod rng;

pub use rng::{SplitMix64, mix64};

pub mod medium;
pub mod medium_bound;
pub mod subsurface_medium;
pub use medium::{DensityKind, MediumDesc, MediumMotion, MediumState, RawGrid};
pub use medium_bound::{ClosedMesh, MediumBound};
pub use subsurface_medium::SubsurfaceMedium;

use glam::{Mat4, Vec2, Vec3};
use serde::{Deserialize, Serialize};

/// Shared geometry in object space. One BLAS is built per mesh, once.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Mesh {
    pub name: String,
    pub positions: Vec<Vec3>,
    /// Per-vertex shading normals; empty means flat (geometric) normals.
    pub normals: Vec<Vec3>,
    /// Per-vertex texture coordinates; empty means all zero.
    pub uvs: Vec<Vec2>,
    pub indices: Vec<[u32; 3]>,
}

impl Mesh {
    /// The square of side 2 * half in the y = 0 plane, facing +y (counter-clockwise seen from
    /// above), uvs over [0, 1]^2: the floor of analytic test scenes.
    pub fn plane(half: f32) -> Mesh {
        Mesh {
            name: "plane".into(),
            positions: vec![
                Vec3::new(-half, 0.0, -half),
                Vec3::new(-half, 0.0, half),
                Vec3::new(half, 0.0, half),
                Vec3::new(half, 0.0, -half),
            ],
            normals: vec![],
            uvs: vec![
                Vec2::new(0.0, 0.0),
                Vec2::new(0.0, 1.0),
                Vec2::new(1.0, 1.0),
                Vec2::new(1.0, 0.0),
            ],
            indices: vec![[0, 1, 2], [0, 2, 3]],
        }
    }
}

/// An RGBA8 texture in sRGB encoding (glTF base colour textures are sRGB).
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Texture {
    pub name: String,
    pub width: u32,
    pub height: u32,
    pub rgba8: Vec<u8>,
}

/// glTF metallic-roughness material.
#[derive(Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct Material {
    /// Linear base colour (multiplied by the texture when there is one).
    pub base_color: Vec3,
    /// Index into `SceneDesc::textures`.
    pub base_color_texture: Option<u32>,
    /// Emitted radiance; non-zero makes every triangle using it an area light.
    pub emission: Vec3,
    /// Perceptual roughness in [0, 1]; GGX alpha = roughness^2.
    pub roughness: f32,
    pub metallic: f32,
    /// KHR_materials_specular factor: scales the dielectric Fresnel term (F = specular * Schlick(0.04)).
    /// 0 leaves a pure Lambertian diffuse (furnace tests); glTF's default is 1.
    #[serde(default = "one")]
    pub specular: f32,
    /// Screen-space subsurface scattering (sss): set by a scenario's material override.
    /// The path tracer shades the surface as its diffuse base; the SSS method scatters the
    /// demodulated diffuse irradiance of its pixels.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub subsurface: Option<Subsurface>,
}

/// Burley's profile parameters of a material (realtime-sss-thesis.txt, eq. 2.44 Θ3): the diffuse
/// mean free path per channel in scene units; the albedo is the base colour.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Subsurface {
    pub dmfp: Vec3,
}

fn one() -> f32 {
    1.0
}

/// As derived, but `subsurface` only when set: the reference cache hashes materials by their
/// `Debug` form, and a field that is always `None` must not change the keys of existing scenes.
impl std::fmt::Debug for Material {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        let mut d = f.debug_struct("Material");
        d.field("base_color", &self.base_color)
            .field("base_color_texture", &self.base_color_texture)
            .field("emission", &self.emission)
            .field("roughness", &self.roughness)
            .field("metallic", &self.metallic)
            .field("specular", &self.specular);
        if let Some(s) = &self.subsurface {
            d.field("subsurface", s);
        }
        d.finish()
    }
}

impl Default for Material {
    fn default() -> Self {
        Self {
            base_color: Vec3::splat(0.8),
            base_color_texture: None,
            emission: Vec3::ZERO,
            roughness: 1.0,
            metallic: 0.0,
            specular: 1.0,
            subsurface: None,
        }
    }
}

/// One placed copy of a mesh. The TLAS is built over instances.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Instance {
    /// Index into `SceneDesc::meshes`.
    pub mesh: u32,
    /// Index into `SceneDesc::materials`.
    pub material: u32,
    /// Object to world.
    pub transform: Mat4,
}

/// Analytic lights (emissive meshes are lights too, through their material).
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub enum Light {
    /// Light arriving from a cone of directions around `-direction`, `direction` pointing
    /// from the light into the scene. `irradiance` is measured on a surface facing the light.
    Directional { direction: Vec3, irradiance: Vec3, angular_radius: f32 },
    /// Isotropic point light; `intensity` in W/sr.
    Point { position: Vec3, intensity: Vec3 },
    /// Spot light with a smooth falloff between the inner and outer cone half-angles.
    Spot { position: Vec3, direction: Vec3, intensity: Vec3, inner_angle: f32, outer_angle: f32 },
}

/// Pinhole camera.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct Camera {
    pub position: Vec3,
    pub target: Vec3,
    pub up: Vec3,
    /// Vertical field of view in radians.
    pub vfov: f32,
}

impl Default for Camera {
    fn default() -> Self {
        Self {
            position: Vec3::new(0.0, 1.0, 3.0),
            target: Vec3::new(0.0, 1.0, 0.0),
            up: Vec3::Y,
            vfov: 45f32.to_radians(),
        }
    }
}

impl Camera {
    pub fn view(&self) -> Mat4 {
        glam::camera::rh::view::look_at_mat4(self.position, self.target, self.up)
    }

    pub fn projection(&self, aspect: f32) -> Mat4 {
        // wgpu's clip space: z in [0, 1], y up (the DirectX convention).
        glam::camera::rh::proj::directx::perspective(self.vfov, aspect, 0.01, 1000.0)
    }
}

/// Everything one frame renders.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct SceneDesc {
    pub meshes: Vec<Mesh>,
    pub textures: Vec<Texture>,
    pub materials: Vec<Material>,
    pub instances: Vec<Instance>,
    pub lights: Vec<Light>,
    /// Constant environment radiance seen by rays that leave the scene.
    pub environment: Vec3,
    pub camera: Camera,
}

/// Which parts of the scene differ between two consecutive frames, so the renderer uploads only
/// what changed.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct SceneChanges {
    /// Meshes or textures (only on the first frame: geometry is static during a run).
    pub geometry: bool,
    /// Instance transforms, meshes or material indices: the TLAS needs a refit or rebuild.
    pub instances: bool,
    pub materials: bool,
    pub lights: bool,
    pub camera: bool,
    pub environment: bool,
}

impl SceneChanges {
    /// Everything changed (a first frame).
    pub const ALL: SceneChanges = SceneChanges {
        geometry: true,
        instances: true,
        materials: true,
        lights: true,
        camera: true,
        environment: true,
    };

    /// Compares the dynamic parts; geometry is compared by counts only (it is static).
    pub fn between(previous: &SceneDesc, next: &SceneDesc) -> SceneChanges {
        SceneChanges {
            geometry: previous.meshes.len() != next.meshes.len()
                || previous.textures.len() != next.textures.len(),
            instances: previous.instances != next.instances,
            materials: previous.materials != next.materials,
            lights: previous.lights != next.lights,
            camera: previous.camera != next.camera,
            environment: previous.environment != next.environment,
        }
    }

    pub fn any(&self) -> bool {
        *self != SceneChanges::default()
    }

    /// Did the world-space geometry move (TLAS refit/rebuild)?
    pub fn moved(&self) -> bool {
        self.geometry || self.instances
    }
}

#[cfg(test)]
mod material_debug_tests {
    use super::*;

    /// The reference cache hashes `format!("{:?}", materials)`: the form without subsurface is
    /// the derived one of the fields before it was added.
    #[test]
    fn debug_form_without_subsurface_is_unchanged() {
        let m = Material::default();
        assert_eq!(
            format!("{m:?}"),
            "Material { base_color: Vec3(0.8, 0.8, 0.8), base_color_texture: None, emission: Vec3(0.0, 0.0, 0.0), roughness: 1.0, metallic: 0.0, specular: 1.0 }"
        );
        let s = Material { subsurface: Some(Subsurface { dmfp: Vec3::ONE }), ..m };
        assert!(format!("{s:?}").contains("subsurface: Subsurface { dmfp: Vec3(1.0, 1.0, 1.0) }"));
    }
}
