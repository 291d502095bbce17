//! Scenes and a device shared by the GPU tests of the method crates (hash cache, termination
//! cache, sample cache) and render's own.

use glam::{Mat4, Quat, Vec3};
use render::gpu::Gpu;
use render::scene::{Camera, Instance, Light, Material, Mesh, SceneDesc, Texture};
use std::sync::OnceLock;

/// The tests' image size.
pub const W: u32 = 32;
pub const H: u32 = 18;

/// One device for all tests of a binary.
pub fn gpu() -> &'static Gpu {
    static GPU: OnceLock<Gpu> = OnceLock::new();
    GPU.get_or_init(|| Gpu::new().expect("a wgpu adapter (lavapipe on CI)"))
}

/// Axis-aligned box [-1, 1]^3, faces wound to face outwards or inwards (emitters are one-sided).
pub fn box_mesh(inward: bool) -> Mesh {
    let mut positions = vec![];
    let mut indices = vec![];
    for axis in 0..3 {
        for sign in [-1.0f32, 1.0] {
            let n = Vec3::from_array(std::array::from_fn(|i| if i == axis { sign } else { 0.0 }));
            let (u, v) = (
                Vec3::from_array(std::array::from_fn(|i| (i == (axis + 1) % 3) as u8 as f32)),
                Vec3::from_array(std::array::from_fn(|i| (i == (axis + 2) % 3) as u8 as f32)),
            );
            let base = positions.len() as u32;
            for (a, b) in [(-1.0, -1.0), (1.0, -1.0), (1.0, 1.0), (-1.0, 1.0)] {
                positions.push(n + a * u + b * v);
            }
            let mut tris = [[base, base + 1, base + 2], [base, base + 2, base + 3]];
            for t in &mut tris {
                let (p0, p1, p2) =
                    (positions[t[0] as usize], positions[t[1] as usize], positions[t[2] as usize]);
                let outward = (p1 - p0).cross(p2 - p0).dot(n) > 0.0;
                if outward == inward {
                    t.swap(1, 2);
                }
            }
            indices.extend(tris);
        }
    }
    Mesh { name: "box".into(), positions, normals: vec![], uvs: vec![], indices }
}

/// A closed grey room (inward walls, [-2, 2]^3) lit by a panel under the ceiling, with a red
/// box: mostly indirect light, the case a radiance cache is for.
pub fn room_scene() -> SceneDesc {
    let grey = Material { base_color: Vec3::splat(0.6), specular: 0.0, ..Default::default() };
    let red =
        Material { base_color: Vec3::new(0.7, 0.2, 0.1), specular: 0.0, ..Default::default() };
    let light = Material {
        base_color: Vec3::ZERO,
        emission: Vec3::splat(8.0),
        specular: 0.0,
        ..Default::default()
    };
    SceneDesc {
        meshes: vec![box_mesh(true), box_mesh(false), Mesh::plane(0.5)],
        materials: vec![grey, red, light],
        instances: vec![
            Instance { mesh: 0, material: 0, transform: Mat4::from_scale(Vec3::splat(2.0)) },
            Instance {
                mesh: 1,
                material: 1,
                transform: Mat4::from_scale_rotation_translation(
                    Vec3::splat(0.6),
                    Quat::from_rotation_y(0.5),
                    Vec3::new(0.3, -1.4, -0.5),
                ),
            },
            // Facing down.
            Instance {
                mesh: 2,
                material: 2,
                transform: Mat4::from_rotation_translation(
                    Quat::from_rotation_x(std::f32::consts::PI),
                    Vec3::new(0.0, 1.95, 0.0),
                ),
            },
        ],
        camera: Camera {
            position: Vec3::new(0.0, 0.0, 1.9),
            target: Vec3::new(0.0, -0.6, -1.0),
            up: Vec3::Y,
            vfov: 1.1,
        },
        ..Default::default()
    }
}

/// Inside a closed box whose walls (albedo a) all emit Le: L = Le / (1 - a) everywhere.
pub fn furnace() -> (SceneDesc, f32) {
    let (le, a) = (0.5f32, 0.5f32);
    let wall = Material {
        base_color: Vec3::splat(a),
        emission: Vec3::splat(le),
        specular: 0.0,
        ..Default::default()
    };
    let scene = SceneDesc {
        meshes: vec![box_mesh(true)],
        materials: vec![wall],
        instances: vec![Instance {
            mesh: 0,
            material: 0,
            transform: Mat4::from_scale(Vec3::splat(2.0)),
        }],
        camera: Camera {
            position: Vec3::new(0.3, -0.2, 1.0),
            target: Vec3::new(-0.5, 0.1, -2.0),
            up: Vec3::Y,
            vfov: 1.2,
        },
        ..Default::default()
    };
    (scene, le / (1.0 - a))
}

/// One-sided 95% Student-t upper bound of the mean of `x` (n - 1 degrees of freedom, n <= 6).
pub fn upper_bound_of_mean(x: &[f64]) -> f64 {
    const T95: [f64; 5] = [6.314, 2.920, 2.353, 2.132, 2.015];
    let n = x.len() as f64;
    let mean = x.iter().sum::<f64>() / n;
    let sd = (x.iter().map(|v| (v - mean).powi(2)).sum::<f64>() / (n - 1.0)).sqrt();
    mean + T95[x.len() - 2] * sd / n.sqrt()
}

/// The room without its walls: the red box under the panel, open to the environment.
pub fn open_scene() -> SceneDesc {
    let mut scene = room_scene();
    scene.instances.remove(0);
    scene
}

/// [`open_scene`] with an environment, a point light and a glossy checker-textured box: every
/// kind of light and surface (render::scene_features).
pub fn lit_open_scene() -> SceneDesc {
    let mut scene = open_scene();
    scene.environment = Vec3::splat(0.3);
    scene
        .lights
        .push(Light::Point { position: Vec3::new(1.0, 1.0, 1.0), intensity: Vec3::splat(2.0) });
    let (dark, light) = ([40u8, 40, 40, 255], [220u8, 220, 220, 255]);
    scene.textures.push(Texture {
        name: "checker".into(),
        width: 2,
        height: 2,
        rgba8: [dark, light, light, dark].concat(),
    });
    scene.materials[1].base_color_texture = Some(0);
    scene.materials[1].specular = 1.0;
    scene
}
