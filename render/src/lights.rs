//! The light table of path_tracer.wgsl (`GpuLight`, see pt_lights.wgsl): analytic lights first,
//! then every triangle of every instance whose material emits, as an area light sampled by power
//! (luminance(Le) x area) through a cumulative distribution.

use crate::error::RenderError;
use crate::scene::{Light, SceneDesc};
use bytemuck::Zeroable;
use glam::Vec3;

const DIRECTIONAL: u32 = 0;
const POINT: u32 = 1;
const SPOT: u32 = 2;
const TRIANGLE: u32 = 3;

crate::gpu_struct! {
    /// One entry of the light table (texel table `light_table`, @group(0) binding 3, read with
    /// `light(i)`); the meaning of p0, p1, p2, a and b depends on `kind` (see pt_lights.wgsl).
    pub struct GpuLight {
        pub p0: [f32; 3] => "vec3f",
        pub kind: u32 => "u32",
        pub p1: [f32; 3] => "vec3f",
        pub cdf: f32 => "f32",
        pub p2: [f32; 3] => "vec3f",
        pub a: f32 => "f32",
        pub radiance: [f32; 3] => "vec3f",
        pub b: f32 => "f32",
    }
}

const _: () = assert!(size_of::<GpuLight>() == 64);

/// Rec. 709 luminance, the same weights as WGSL `luminance`.
pub fn luminance(c: Vec3) -> f32 {
    c.dot(Vec3::new(0.2126, 0.7152, 0.0722))
}

pub(crate) struct LightTable {
    pub lights: Vec<GpuLight>,
    pub analytic: u32,
    pub emitters: u32,
    /// W = sum over emissive triangles of luminance(Le) x area: the area pdf of an emissive
    /// point is luminance(Le) / W.
    pub emitter_weight: f32,
}

pub(crate) fn build_light_table(scene: &SceneDesc) -> Result<LightTable, RenderError> {
    let mut lights = Vec::new();
    for light in &scene.lights {
        lights.push(match *light {
            Light::Directional { direction, irradiance, angular_radius } => {
                let r = angular_radius.clamp(0.0, std::f32::consts::FRAC_PI_2) as f64;
                // 1 - cos r in a form that keeps precision for the sun's ~0.005 rad.
                let one_minus_cos = 2.0 * (0.5 * r).sin().powi(2);
                let disk =
                    if r > 0.0 { 1.0 / (std::f64::consts::PI * r.sin().powi(2)) } else { 0.0 };
                GpuLight {
                    kind: DIRECTIONAL,
                    p1: direction.normalize_or(Vec3::NEG_Y).to_array(),
                    radiance: irradiance.to_array(),
                    a: one_minus_cos as f32,
                    b: disk as f32,
                    ..Zeroable::zeroed()
                }
            }
            Light::Point { position, intensity } => GpuLight {
                kind: POINT,
                p0: position.to_array(),
                radiance: intensity.to_array(),
                ..Zeroable::zeroed()
            },
            Light::Spot { position, direction, intensity, inner_angle, outer_angle } => GpuLight {
                kind: SPOT,
                p0: position.to_array(),
                p1: direction.normalize_or(Vec3::NEG_Y).to_array(),
                radiance: intensity.to_array(),
                a: outer_angle.cos(),
                b: inner_angle.cos(),
                ..Zeroable::zeroed()
            },
        });
    }
    let analytic = lights.len() as u32;

    let mut weights = Vec::new();
    for (i, inst) in scene.instances.iter().enumerate() {
        let Some(material) = scene.materials.get(inst.material as usize) else {
            return Err(RenderError::Scene(format!(
                "instance {i} uses material {}, but the scene has {} materials",
                inst.material,
                scene.materials.len()
            )));
        };
        let le = material.emission;
        if !(luminance(le) > 0.0) {
            continue;
        }
        let Some(mesh) = scene.meshes.get(inst.mesh as usize) else {
            return Err(RenderError::Scene(format!(
                "instance {i} uses mesh {}, but the scene has {} meshes",
                inst.mesh,
                scene.meshes.len()
            )));
        };
        for (t, tri) in mesh.indices.iter().enumerate() {
            let mut v = [Vec3::ZERO; 3];
            for k in 0..3 {
                let p = mesh.positions.get(tri[k] as usize).ok_or_else(|| {
                    RenderError::Scene(format!(
                        "mesh '{}' triangle {t} uses vertex {}, but it has {} positions",
                        mesh.name,
                        tri[k],
                        mesh.positions.len()
                    ))
                })?;
                v[k] = inst.transform.transform_point3(*p);
            }
            let area = 0.5 * (v[1] - v[0]).cross(v[2] - v[0]).length();
            if !(area > 0.0) {
                continue; // degenerate: never hit, never sampled
            }
            weights.push(luminance(le) as f64 * area as f64);
            lights.push(GpuLight {
                kind: TRIANGLE,
                p0: v[0].to_array(),
                p1: v[1].to_array(),
                p2: v[2].to_array(),
                radiance: le.to_array(),
                ..Zeroable::zeroed()
            });
        }
    }
    let total: f64 = weights.iter().sum();
    let mut running = 0.0;
    let emitters = weights.len();
    for (k, w) in weights.iter().enumerate() {
        running += w;
        lights[analytic as usize + k].cdf =
            if k + 1 == emitters { 1.0 } else { (running / total) as f32 };
    }
    if lights.is_empty() {
        lights.push(GpuLight::zeroed()); // storage buffers may not be empty
    }
    Ok(LightTable { lights, analytic, emitters: emitters as u32, emitter_weight: total as f32 })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::scene::{Instance, Material, Mesh};
    use glam::Mat4;

    fn triangle_mesh() -> Mesh {
        Mesh {
            name: "tri".into(),
            positions: vec![Vec3::ZERO, Vec3::X, Vec3::Z],
            indices: vec![[0, 1, 2]],
            ..Default::default()
        }
    }

    #[test]
    fn emissive_triangles_are_chosen_by_power() {
        // Two emitters: the second twice as bright and (scaled by 3 in x) three times as large.
        let scene = SceneDesc {
            meshes: vec![triangle_mesh()],
            materials: vec![
                Material { emission: Vec3::ONE, ..Default::default() },
                Material { emission: Vec3::splat(2.0), ..Default::default() },
                Material::default(),
            ],
            instances: vec![
                Instance { mesh: 0, material: 0, transform: Mat4::IDENTITY },
                Instance {
                    mesh: 0,
                    material: 1,
                    transform: Mat4::from_scale(Vec3::new(3.0, 1.0, 1.0)),
                },
                Instance { mesh: 0, material: 2, transform: Mat4::IDENTITY },
            ],
            lights: vec![Light::Point { position: Vec3::Y, intensity: Vec3::ONE }],
            ..Default::default()
        };
        let t = build_light_table(&scene).unwrap();
        assert_eq!((t.analytic, t.emitters), (1, 2));
        // W = 1 * 0.5 + 2 * 1.5
        assert!((t.emitter_weight - 3.5).abs() < 1e-6, "{}", t.emitter_weight);
        assert!((t.lights[1].cdf - 0.5 / 3.5).abs() < 1e-6);
        assert_eq!(t.lights[2].cdf, 1.0);
        // World-space vertices of the scaled instance.
        assert_eq!(t.lights[2].p1, [3.0, 0.0, 0.0]);
    }

    #[test]
    fn sun_cone_constants_keep_precision() {
        let r = 0.00465f32;
        let scene = SceneDesc {
            lights: vec![Light::Directional {
                direction: Vec3::NEG_Y,
                irradiance: Vec3::ONE,
                angular_radius: r,
            }],
            ..Default::default()
        };
        let l = build_light_table(&scene).unwrap().lights[0];
        let one_minus_cos = 1.0 - (r as f64).cos();
        assert!((l.a as f64 / one_minus_cos - 1.0).abs() < 1e-5);
        // Disk radiance x solid angle = irradiance (for the sun's tiny cone, to first order).
        let omega = 2.0 * std::f64::consts::PI * one_minus_cos;
        assert!((l.b as f64 * omega - 1.0).abs() < 1e-4, "{}", l.b as f64 * omega);
    }

    #[test]
    fn dangling_indices_are_reported() {
        let scene = SceneDesc {
            meshes: vec![triangle_mesh()],
            materials: vec![Material { emission: Vec3::ONE, ..Default::default() }],
            instances: vec![Instance { mesh: 4, material: 0, transform: Mat4::IDENTITY }],
            ..Default::default()
        };
        let e = build_light_table(&scene).err().unwrap().to_string();
        assert!(e.contains("instance 0 uses mesh 4"), "{e}");
    }
}
