//! The matrix's scenes: one small stage (a floor, two walls and a box) varied one feature at a
//! time: each light type, the roughness of metal and dielectric, a texture, the depth limit.

use glam::{Mat4, Quat, Vec2, Vec3};
use render::scene::{Camera, Instance, Light, Material, Mesh, SceneDesc, Texture};
use scene::{DensityKind, MediumDesc};
use testkit::test_scenes::box_mesh;

/// Image side in pixels (square images).
pub const SIZE: u32 = 16;

/// One scene of the matrix: our settings and the samples per pixel each renderer takes.
pub struct Case {
    pub name: &'static str,
    pub scene: SceneDesc,
    /// Our `PathTracerSettings::max_depth` (Mitsuba's is one more).
    pub max_depth: u32,
    pub spp: u32,
    /// Participating media: rendered by our volumetric path tracer (the references' renderer
    /// for scenes with media) and Mitsuba's `volpath`.
    pub media: Vec<MediumDesc>,
}

const FLOOR: u32 = 0;
const BACK: u32 = 1;
const LEFT: u32 = 2;
const BOX: u32 = 3;

fn lambert(c: Vec3) -> Material {
    Material { base_color: c, specular: 0.0, metallic: 0.0, ..Default::default() }
}

fn emitter(le: Vec3) -> Material {
    Material { base_color: Vec3::ZERO, emission: le, specular: 0.0, ..Default::default() }
}

/// The stage: a 3 x 3 floor, a blue back wall, a red left wall and a box, seen from the front.
/// Materials: 0 floor, 1 back wall, 2 left wall, 3 box. Flat normals only, so that neither
/// renderer's handling of shading normals enters.
fn stage() -> SceneDesc {
    let plane = Mesh::plane(1.5);
    SceneDesc {
        meshes: vec![plane, box_mesh(false)],
        materials: vec![
            lambert(Vec3::splat(0.6)),
            lambert(Vec3::new(0.2, 0.4, 0.7)),
            lambert(Vec3::new(0.7, 0.15, 0.1)),
            lambert(Vec3::new(0.8, 0.7, 0.3)),
        ],
        instances: vec![
            Instance { mesh: 0, material: FLOOR, transform: Mat4::IDENTITY },
            Instance {
                mesh: 0,
                material: BACK,
                transform: Mat4::from_rotation_translation(
                    Quat::from_rotation_x(std::f32::consts::FRAC_PI_2),
                    Vec3::new(0.0, 1.5, -1.5),
                ),
            },
            Instance {
                mesh: 0,
                material: LEFT,
                transform: Mat4::from_rotation_translation(
                    Quat::from_rotation_z(-std::f32::consts::FRAC_PI_2),
                    Vec3::new(-1.5, 1.5, 0.0),
                ),
            },
            Instance {
                mesh: 1,
                material: BOX,
                transform: Mat4::from_scale_rotation_translation(
                    Vec3::splat(0.4),
                    Quat::from_rotation_y(0.5),
                    Vec3::new(0.35, 0.4, -0.3),
                ),
            },
        ],
        camera: Camera {
            position: Vec3::new(0.4, 1.4, 3.3),
            target: Vec3::new(-0.1, 0.6, 0.0),
            up: Vec3::Y,
            vfov: 0.8,
        },
        ..Default::default()
    }
}

/// A downward-facing square emitter of side 2 * half at `centre`.
fn add_panel(scene: &mut SceneDesc, centre: Vec3, half: f32, le: Vec3) {
    let mesh = scene.meshes.len() as u32;
    scene.meshes.push(Mesh::plane(half));
    let material = scene.materials.len() as u32;
    scene.materials.push(emitter(le));
    scene.instances.push(Instance {
        mesh,
        material,
        transform: Mat4::from_rotation_translation(
            Quat::from_rotation_x(std::f32::consts::PI),
            centre,
        ),
    });
}

fn point() -> Light {
    Light::Point { position: Vec3::new(0.9, 2.3, 1.2), intensity: Vec3::new(6.0, 5.5, 5.0) }
}

fn with_panel() -> SceneDesc {
    let mut s = stage();
    add_panel(&mut s, Vec3::new(0.0, 2.4, 0.0), 0.5, Vec3::new(6.0, 6.0, 5.0));
    s
}

/// The floor and the box in `m` (the subject of the material cases), lit by the panel, a
/// point light and a dim sky: glossy reflections of an area light, NEE of a delta light.
fn material_case(m: Material) -> SceneDesc {
    let mut s = with_panel();
    s.materials[FLOOR as usize] = m;
    s.materials[BOX as usize] = m;
    s.lights.push(point());
    s.environment = Vec3::new(0.10, 0.12, 0.15);
    s
}

/// A 4 x 3 texture of distinct colours, so that a flipped, transposed or offset lookup and a
/// wrong sRGB decode change the image.
fn texture() -> Texture {
    let colours: [[u8; 3]; 12] = [
        [230, 40, 40],
        [40, 200, 60],
        [50, 60, 220],
        [240, 240, 240],
        [20, 20, 20],
        [200, 180, 40],
        [120, 30, 160],
        [30, 170, 170],
        [128, 128, 128],
        [250, 120, 10],
        [10, 90, 40],
        [180, 200, 250],
    ];
    Texture {
        name: "colours".into(),
        width: 4,
        height: 3,
        rgba8: colours.iter().flat_map(|c| [c[0], c[1], c[2], 255]).collect(),
    }
}

pub fn matrix() -> Vec<Case> {
    let many = 64;
    let case = |name, scene, max_depth, spp| Case { name, scene, max_depth, spp, media: vec![] };
    let mut cases = Vec::new();

    let mut s = stage();
    s.lights.push(point());
    cases.push(case("point", s, many, 1024));

    let mut s = stage();
    s.lights.push(Light::Spot {
        position: Vec3::new(-0.4, 2.6, 1.0),
        direction: (Vec3::new(0.3, 0.0, -0.4) - Vec3::new(-0.4, 2.6, 1.0)).normalize(),
        intensity: Vec3::new(8.0, 7.0, 6.0),
        inner_angle: 0.4,
        outer_angle: 0.4,
    });
    cases.push(case("spot", s, many, 1024));

    let mut s = stage();
    s.lights.push(Light::Directional {
        direction: Vec3::new(0.5, -1.0, -0.4).normalize(),
        irradiance: Vec3::new(2.0, 1.9, 1.7),
        angular_radius: 0.0,
    });
    cases.push(case("directional", s, many, 1024));

    cases.push(case("area", with_panel(), many, 1024));
    cases.push(case("area_depth_1", with_panel(), 1, 1024));
    cases.push(case("area_depth_2", with_panel(), 2, 1024));

    // Emissive meshes: a small warm box on the floor and a cool strip on the wall, triangles of
    // different power for the light CDF.
    let mut s = stage();
    let m = s.materials.len() as u32;
    s.materials.push(emitter(Vec3::new(9.0, 4.0, 1.5)));
    s.instances.push(Instance {
        mesh: 1,
        material: m,
        transform: Mat4::from_scale_rotation_translation(
            Vec3::new(0.15, 0.15, 0.25),
            Quat::from_rotation_y(-0.3),
            Vec3::new(-0.7, 0.15, 0.5),
        ),
    });
    s.materials.push(emitter(Vec3::new(1.0, 3.0, 6.0)));
    s.meshes.push(Mesh {
        name: "strip".into(),
        positions: vec![
            Vec3::new(-1.2, 1.6, -1.49),
            Vec3::new(1.2, 1.6, -1.49),
            Vec3::new(1.2, 1.8, -1.49),
            Vec3::new(-1.2, 1.8, -1.49),
        ],
        indices: vec![[0, 1, 2], [0, 2, 3]],
        ..Default::default()
    });
    s.instances.push(Instance { mesh: 2, material: m + 1, transform: Mat4::IDENTITY });
    cases.push(case("emissive_mesh", s, many, 1024));

    let mut s = stage();
    s.environment = Vec3::new(0.6, 0.7, 0.9);
    cases.push(case("environment", s, many, 1024));

    let mut s = with_panel();
    s.textures.push(texture());
    s.meshes[0].uvs = s.meshes[0].uvs.iter().map(|uv| *uv * Vec2::new(1.5, 1.0)).collect();
    s.materials[FLOOR as usize] =
        Material { base_color: Vec3::ONE, base_color_texture: Some(0), ..lambert(Vec3::ONE) };
    cases.push(case("texture", s, many, 1024));

    // Metal from a mirror to fully rough, and a dielectric (F0 = 0.04) over a coloured base.
    let metal = |c: Vec3, r: f32| Material {
        base_color: c,
        roughness: r,
        metallic: 1.0,
        specular: 1.0,
        ..Default::default()
    };
    let dielectric = |r: f32| Material {
        base_color: Vec3::new(0.2, 0.45, 0.7),
        roughness: r,
        metallic: 0.0,
        specular: 1.0,
        ..Default::default()
    };
    let gold = Vec3::new(1.0, 0.78, 0.34);
    // The mirror without the point light: its reflection in a mirror (a caustic of a delta
    // light through a delta BSDF) is a path neither renderer can sample, and ours, whose mirror
    // is a GGX lobe of alpha 1e-3, samples it with unbounded variance.
    let mut mirror = material_case(metal(Vec3::ONE, 0.0));
    mirror.lights.clear();
    cases.push(case("metal_mirror", mirror, many, 1024));
    cases.push(case("metal_r0.2", material_case(metal(gold, 0.2)), many, 256));
    cases.push(case("metal_r0.5", material_case(metal(gold, 0.5)), many, 256));
    cases.push(case("metal_r1", material_case(metal(gold, 1.0)), many, 256));
    cases.push(case("dielectric_r0.2", material_case(dielectric(0.2)), many, 256));
    cases.push(case("dielectric_r0.6", material_case(dielectric(0.6)), many, 256));
    cases.push(case("dielectric_r1", material_case(dielectric(1.0)), many, 256));

    // A homogeneous scattering cube in front of the box, lit by the panel and the point light.
    let mut s = with_panel();
    s.lights.push(point());
    let fog = MediumDesc {
        name: "fog".into(),
        kind: DensityKind::Homogeneous,
        box_min: Vec3::new(-1.2, 0.3, 0.1),
        box_max: Vec3::new(-0.1, 1.4, 1.2),
        bound: Default::default(),
        sigma_t: 1.5,
        resolution: (8, 8, 8),
        albedo: Vec3::new(0.9, 0.7, 0.5),
        emission: None,
        motion: Default::default(),
        super_voxel: 16,
    };
    cases.push(Case { media: vec![fog.clone()], ..case("medium", s, many, 512) });

    // A heterogeneous medium: an fBm cloud baked to a grid that is not a cube in voxels
    // (12 x 10 x 8, so that an axis swapped in the export changes the image) nor in space, with
    // 4^3-voxel super-voxels (several local majorants); Mitsuba gets the same grid (see
    // bench::mitsuba). Peak extinction 6: optical depths up to about 4 through the box.
    let mut s = with_panel();
    s.lights.push(point());
    let cloud = MediumDesc {
        name: "cloud".into(),
        kind: DensityKind::Cloud { octaves: 3, frequency: 2.0, seed: 5 },
        box_min: Vec3::new(-1.3, 0.2, 0.0),
        box_max: Vec3::new(-0.1, 1.3, 0.9),
        sigma_t: 6.0,
        resolution: (12, 10, 8),
        albedo: Vec3::new(0.8, 0.6, 0.4),
        super_voxel: 4,
        ..fog
    };
    cases.push(Case { media: vec![cloud], ..case("medium_grid", s, many, 512) });

    // Smooth shading normals: an ellipsoid as an 8 x 6 UV sphere (facets of two pixels and more) with the exact normals at its
    // vertices, turned and uniformly scaled by its instance (normals through the inverse
    // transpose), lit by the point light and the panel. The stretch is in the mesh, not the
    // instance: under a non-uniform instance scale the two renderers interpolate differently
    // (ours normalize(N (b0 n0 + b1 n1 + b2 n2)), as pbrt-v4; Mitsuba normalizes each N ni
    // first), the same under a uniform one. Direct light only: where the shading and geometric
    // normals disagree about a direction's side the renderers differ by design (ours requires
    // both to agree, Mitsuba's BSDFs see the shading frame only; a path that Mitsuba continues
    // into the closed ellipsoid, ours ends), and direct light from the camera's side never
    // meets that case: a direction below the facet is occluded by the ellipsoid itself.
    let mut s = with_panel();
    s.lights.push(point());
    let mesh = s.meshes.len() as u32;
    s.meshes.push(uv_ellipsoid(8, 6, Vec3::new(0.9, 0.7, 0.8)));
    s.materials.push(lambert(Vec3::new(0.75, 0.75, 0.7)));
    s.instances.push(Instance {
        mesh,
        material: s.materials.len() as u32 - 1,
        transform: Mat4::from_scale_rotation_translation(
            Vec3::splat(0.8),
            Quat::from_rotation_y(0.4),
            Vec3::new(-0.45, 0.57, 0.5),
        ),
    });
    cases.push(case("smooth_normals", s, 1, 1024));
    cases
}

/// The ellipsoid of semi-axes `radii` as `segments` x `rings` quads (two triangles each, the
/// poles' degenerate ones dropped), counter-clockwise seen from outside, with the ellipsoid's
/// unit normals at the vertices: a coarse polyhedron whose shading follows the smooth surface.
fn uv_ellipsoid(segments: u32, rings: u32, radii: Vec3) -> Mesh {
    let (mut positions, mut normals) = (Vec::new(), Vec::new());
    for r in 0..=rings {
        let theta = std::f32::consts::PI * r as f32 / rings as f32;
        for k in 0..=segments {
            let phi = std::f32::consts::TAU * k as f32 / segments as f32;
            let u = Vec3::new(theta.sin() * phi.cos(), theta.cos(), -theta.sin() * phi.sin());
            positions.push(u * radii);
            normals.push((u / radii).normalize());
        }
    }
    let at = |r: u32, k: u32| r * (segments + 1) + k;
    let mut indices = Vec::new();
    for r in 0..rings {
        for k in 0..segments {
            let (a, b, c, d) = (at(r, k), at(r + 1, k), at(r + 1, k + 1), at(r, k + 1));
            if r > 0 {
                indices.push([a, b, d]);
            }
            if r + 1 < rings {
                indices.push([b, c, d]);
            }
        }
    }
    Mesh { name: "uv_ellipsoid".into(), positions, normals, uvs: vec![], indices }
}
