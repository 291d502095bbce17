//! The SSS pass's noise-free irradiance (sss::direct): the WGSL pass against its CPU twin on a
//! tiny image, and against the closed form E/π of a directional light on a floor.
//!
//! The scene: a floor, a box standing on it (its shadows), a tilted quad with per-vertex normals
//! (interpolated shading normals), lit by a point, a spot and a directional light; every light
//! leaves a shadow of the box on the floor, so a pass that ignores visibility, a light kind, the
//! spot's cone or the shading normal differs from the twin. Bound: f32 rounding (the twin runs
//! the same watertight ray-triangle test and the same light formulas; BVH traversal order does
//! not change which hit is closest), 1e-4 relative.

use glam::{Mat4, Vec3};
use render::path_tracer::PathTracerSettings;
use render::scene::{Camera, Instance, Light, Material, Mesh, SceneDesc};
use render::scene_gpu::SceneGpu;
use sss::direct::{DirectIrradiancePass, direct_irradiance};
use testkit::test_scenes::{box_mesh, gpu};

const W: u32 = 24;
const H: u32 = 16;

fn tilted_quad() -> Mesh {
    let mut m = Mesh::plane(0.5);
    // Normals leaning outwards at two corners: the shading normal varies over the quad.
    m.normals = vec![
        Vec3::new(-0.5, 1.0, -0.5).normalize(),
        Vec3::new(0.0, 1.0, 0.0),
        Vec3::new(0.5, 1.0, 0.5).normalize(),
        Vec3::new(0.0, 1.0, 0.0),
    ];
    m
}

fn scene(lights: Vec<Light>) -> SceneDesc {
    let grey = Material { base_color: Vec3::splat(0.5), specular: 0.0, ..Default::default() };
    SceneDesc {
        meshes: vec![Mesh::plane(3.0), box_mesh(false), tilted_quad()],
        materials: vec![grey],
        instances: vec![
            Instance { mesh: 0, material: 0, transform: Mat4::IDENTITY },
            Instance {
                mesh: 1,
                material: 0,
                transform: Mat4::from_translation(Vec3::new(0.2, 0.3, 0.1))
                    * Mat4::from_scale(Vec3::splat(0.3)),
            },
            Instance {
                mesh: 2,
                material: 0,
                transform: Mat4::from_translation(Vec3::new(-1.2, 0.4, 0.3))
                    * Mat4::from_rotation_z(0.4),
            },
        ],
        lights,
        camera: Camera {
            position: Vec3::new(0.0, 3.0, 2.5),
            target: Vec3::new(0.0, 0.0, 0.0),
            up: Vec3::Y,
            vfov: 60f32.to_radians(),
        },
        ..Default::default()
    }
}

fn three_lights() -> Vec<Light> {
    vec![
        Light::Point { position: Vec3::new(1.5, 2.0, 1.0), intensity: Vec3::new(3.0, 2.0, 1.0) },
        Light::Spot {
            position: Vec3::new(-0.5, 2.5, -0.5),
            direction: Vec3::new(0.2, -1.0, 0.3),
            intensity: Vec3::new(1.0, 2.0, 4.0),
            inner_angle: 0.3,
            outer_angle: 0.6,
        },
        Light::Directional {
            direction: Vec3::new(-0.4, -1.0, -0.2),
            irradiance: Vec3::splat(0.7),
            angular_radius: 0.01,
        },
    ]
}

fn gpu_image(desc: &SceneDesc) -> Vec<[f32; 4]> {
    let settings = PathTracerSettings { width: W, height: H, max_depth: 1, rr_start_depth: 3 };
    let scene = SceneGpu::new(gpu(), desc, settings).expect("scene");
    let mut pass = DirectIrradiancePass::new(gpu(), &scene).expect("pass");
    pass.render(gpu(), &scene, 0).expect("render").0
}

#[test]
fn the_gpu_direct_irradiance_matches_its_cpu_twin() {
    let desc = scene(three_lights());
    let gpu_e = gpu_image(&desc);
    let cpu_e = direct_irradiance(&desc, W, H);
    let mut worst = 0f32;
    for (i, (g, c)) in gpu_e.iter().zip(&cpu_e).enumerate() {
        for k in 0..3 {
            let err = (g[k] - c[k]).abs() / (1e-3 + c[k].abs());
            assert!(err <= 1e-4, "pixel {i} channel {k}: GPU {} CPU {}", g[k], c[k]);
            worst = worst.max(err);
        }
        assert_eq!(g[3], 0.0);
    }
    // Each light's shadow is in the image: the box removed changes the twin for every light.
    let mut open = desc.clone();
    open.instances.remove(1);
    for (k, light) in three_lights().into_iter().enumerate() {
        let (mut with, mut without) = (scene(vec![light]), open.clone());
        without.lights = vec![light];
        with.instances = desc.instances.clone();
        let shadowed = direct_irradiance(&with, W, H)
            .iter()
            .zip(direct_irradiance(&without, W, H))
            .filter(|(a, b)| a[0] < b[0])
            .count();
        assert!(shadowed >= 2, "light {k}: {shadowed} shadowed pixels");
    }
    eprintln!("worst relative difference {worst:e}");
}

/// A delta directional light from straight above on the floor: E/π where the floor sees it, 0
/// in the box's shadow (the box's top face too is E/π).
#[test]
fn a_directional_light_gives_e_over_pi_on_the_floor() {
    let e = 0.9f32;
    let mut desc = scene(vec![Light::Directional {
        direction: Vec3::NEG_Y,
        irradiance: Vec3::splat(e),
        angular_radius: 0.0,
    }]);
    desc.instances.truncate(2);
    let image = gpu_image(&desc);
    let lit = e * std::f32::consts::FRAC_1_PI;
    let (mut n_lit, mut n_dark) = (0, 0);
    for (i, p) in image.iter().enumerate() {
        // Floor or the box's top: E/π; the box's sides (vertical): 0; the box's shadow: 0.
        if (p[0] - lit).abs() <= 1e-6 * lit {
            n_lit += 1;
        } else {
            assert_eq!(p[0], 0.0, "pixel {i}: {} is neither E/π = {lit} nor 0", p[0]);
            n_dark += 1;
        }
    }
    assert!(n_lit > 200 && n_dark > 0, "lit {n_lit}, dark {n_dark}");
}
