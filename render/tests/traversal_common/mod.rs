//! The traversal tests' scenes (a glTF torus, a hairball, transformed instances), their rays,
//! and the comparison of a GPU traversal's hits with a CPU reference's (itself checked against
//! brute force). Shared with the bench crate's BVH2 traversal test.
#![allow(dead_code)]

use std::path::{Path, PathBuf};

use glam::{Mat4, Quat, Vec2, Vec3};
use render::bvh::{
    Hit, InstanceTransforms, RayQuery, SceneBvh, SplitMix64, WatertightRay, intersect_triangle,
    random_rays,
};
use render::gpu::Gpu;
use render::scene::{Instance, Mesh, SceneDesc};

pub const RAYS: usize = 3000;

pub fn gpu() -> Gpu {
    Gpu::new().expect("a wgpu adapter (lavapipe on CI)")
}

// ---------------------------------------------------------------- scenes

pub fn torus(major: f32, minor: f32, rings: u32, sides: u32) -> Mesh {
    let mut m = Mesh { name: "torus".into(), ..Default::default() };
    for i in 0..=rings {
        let u = std::f32::consts::TAU * i as f32 / rings as f32;
        for j in 0..=sides {
            let v = std::f32::consts::TAU * j as f32 / sides as f32;
            let n = Vec3::new(u.cos() * v.cos(), v.sin(), u.sin() * v.cos());
            m.positions.push(Vec3::new(major * u.cos(), 0.0, major * u.sin()) + minor * n);
            m.normals.push(n);
            m.uvs.push(Vec2::new(i as f32 / rings as f32, j as f32 / sides as f32));
        }
    }
    let at = |i: u32, j: u32| i * (sides + 1) + j;
    for i in 0..rings {
        for j in 0..sides {
            m.indices.push([at(i, j), at(i, j + 1), at(i + 1, j + 1)]);
            m.indices.push([at(i, j), at(i + 1, j + 1), at(i + 1, j)]);
        }
    }
    m
}

/// Writes `mesh` as a glTF 2.0 file (JSON + .bin) under a node with rotation, non-uniform scale
/// and translation; returns the .gltf path.
pub fn write_gltf(
    dir: &Path,
    mesh: &Mesh,
    rotation: Quat,
    scale: Vec3,
    translation: Vec3,
) -> PathBuf {
    std::fs::create_dir_all(dir).unwrap();
    let mut bin: Vec<u8> = Vec::new();
    bin.extend(mesh.positions.iter().flat_map(|p| p.to_array()).flat_map(f32::to_le_bytes));
    let normals_offset = bin.len();
    bin.extend(mesh.normals.iter().flat_map(|p| p.to_array()).flat_map(f32::to_le_bytes));
    let indices_offset = bin.len();
    bin.extend(mesh.indices.iter().flatten().flat_map(|i| i.to_le_bytes()));
    std::fs::write(dir.join("torus.bin"), &bin).unwrap();
    let (lo, hi) =
        mesh.positions.iter().fold((Vec3::MAX, Vec3::MIN), |(lo, hi), p| (lo.min(*p), hi.max(*p)));
    let n = mesh.positions.len();
    let json = format!(
        r#"{{
  "asset": {{ "version": "2.0" }},
  "scene": 0,
  "scenes": [{{ "nodes": [0] }}],
  "nodes": [{{ "mesh": 0, "rotation": [{}, {}, {}, {}], "scale": [{}, {}, {}], "translation": [{}, {}, {}] }}],
  "meshes": [{{ "name": "torus", "primitives": [{{ "attributes": {{ "POSITION": 0, "NORMAL": 1 }}, "indices": 2 }}] }}],
  "buffers": [{{ "uri": "torus.bin", "byteLength": {} }}],
  "bufferViews": [
    {{ "buffer": 0, "byteOffset": 0, "byteLength": {}, "target": 34962 }},
    {{ "buffer": 0, "byteOffset": {}, "byteLength": {}, "target": 34962 }},
    {{ "buffer": 0, "byteOffset": {}, "byteLength": {}, "target": 34963 }}
  ],
  "accessors": [
    {{ "bufferView": 0, "componentType": 5126, "count": {n}, "type": "VEC3", "min": [{}, {}, {}], "max": [{}, {}, {}] }},
    {{ "bufferView": 1, "componentType": 5126, "count": {n}, "type": "VEC3" }},
    {{ "bufferView": 2, "componentType": 5125, "count": {}, "type": "SCALAR" }}
  ]
}}"#,
        rotation.x,
        rotation.y,
        rotation.z,
        rotation.w,
        scale.x,
        scale.y,
        scale.z,
        translation.x,
        translation.y,
        translation.z,
        bin.len(),
        normals_offset,
        normals_offset,
        indices_offset - normals_offset,
        indices_offset,
        bin.len() - indices_offset,
        lo.x,
        lo.y,
        lo.z,
        hi.x,
        hi.y,
        hi.z,
        mesh.indices.len() * 3,
    );
    let path = dir.join("torus.gltf");
    std::fs::write(&path, json).unwrap();
    path
}

/// Loads every mesh primitive of every node of a glTF file as (mesh, instance).
pub fn load_gltf(path: &Path) -> SceneDesc {
    let (doc, buffers, _) =
        gltf::import(path).unwrap_or_else(|e| panic!("{}: {e}", path.display()));
    let mut scene = SceneDesc::default();
    for node in doc.nodes() {
        let Some(mesh) = node.mesh() else { continue };
        let transform = Mat4::from_cols_array_2d(&node.transform().matrix());
        for primitive in mesh.primitives() {
            let reader = primitive.reader(|b| Some(&buffers[b.index()]));
            let positions: Vec<Vec3> =
                reader.read_positions().expect("POSITION").map(Vec3::from).collect();
            let normals: Vec<Vec3> =
                reader.read_normals().map(|n| n.map(Vec3::from).collect()).unwrap_or_default();
            let flat: Vec<u32> = reader.read_indices().expect("indices").into_u32().collect();
            let indices = flat.chunks_exact(3).map(|c| [c[0], c[1], c[2]]).collect();
            scene.instances.push(Instance {
                mesh: scene.meshes.len() as u32,
                material: 0,
                transform,
            });
            scene.meshes.push(Mesh {
                name: mesh.name().unwrap_or("gltf").into(),
                positions,
                normals,
                uvs: Vec::new(),
                indices,
            });
        }
    }
    scene
}

/// Thin random strands: each a random walk of segments, each segment a triangular prism.
pub fn hairball(strands: u32, segments: u32, radius: f32, seed: u64) -> Mesh {
    let mut rng = SplitMix64::new(seed);
    let mut m = Mesh { name: "hairball".into(), ..Default::default() };
    for _ in 0..strands {
        let mut p = Vec3::new(rng.range(-1.0, 1.0), rng.range(-1.0, 1.0), rng.range(-1.0, 1.0));
        let mut dir = rng.unit_vector();
        for _ in 0..segments {
            dir = (dir + 0.5 * rng.unit_vector()).normalize();
            let q = p + 0.2 * dir;
            let side = dir.any_orthonormal_vector();
            let up = dir.cross(side);
            let ring = |c: Vec3| -> [Vec3; 3] {
                [0.0f32, 1.0, 2.0].map(|k| {
                    let a = k * std::f32::consts::TAU / 3.0;
                    c + radius * (a.cos() * side + a.sin() * up)
                })
            };
            let base = m.positions.len() as u32;
            m.positions.extend(ring(p));
            m.positions.extend(ring(q));
            for k in 0..3 {
                let (a, b) = (k, (k + 1) % 3);
                m.indices.push([base + a, base + b, base + 3 + b]);
                m.indices.push([base + a, base + 3 + b, base + 3 + a]);
            }
            p = q;
        }
    }
    m
}

pub fn cube() -> Mesh {
    let p: Vec<Vec3> = (0..8)
        .map(|i| Vec3::new((i & 1) as f32, ((i >> 1) & 1) as f32, ((i >> 2) & 1) as f32) - 0.5)
        .collect();
    let quads =
        [[0, 2, 3, 1], [4, 5, 7, 6], [0, 1, 5, 4], [2, 6, 7, 3], [0, 4, 6, 2], [1, 3, 7, 5]];
    let indices = quads.iter().flat_map(|q| [[q[0], q[1], q[2]], [q[0], q[2], q[3]]]).collect();
    Mesh { name: "cube".into(), positions: p, normals: Vec::new(), uvs: Vec::new(), indices }
}

pub fn quad() -> Mesh {
    Mesh {
        name: "quad".into(),
        positions: vec![
            Vec3::new(-1.0, 0.0, -1.0),
            Vec3::new(1.0, 0.0, -1.0),
            Vec3::new(1.0, 0.0, 1.0),
            Vec3::new(-1.0, 0.0, 1.0),
        ],
        normals: vec![Vec3::Y; 4],
        uvs: vec![
            Vec2::new(0.0, 0.0),
            Vec2::new(1.0, 0.0),
            Vec2::new(1.0, 1.0),
            Vec2::new(0.0, 1.0),
        ],
        indices: vec![[0, 2, 1], [0, 3, 2]],
    }
}

pub fn random_transform(rng: &mut SplitMix64, mirrored: bool) -> Mat4 {
    let rotation = Quat::from_axis_angle(rng.unit_vector(), rng.range(0.0, std::f32::consts::TAU));
    let mut scale = Vec3::new(rng.range(0.3, 2.0), rng.range(0.3, 2.0), rng.range(0.3, 2.0));
    if mirrored {
        scale.x = -scale.x;
    }
    let translation = Vec3::new(rng.range(-3.0, 3.0), rng.range(-3.0, 3.0), rng.range(-3.0, 3.0));
    Mat4::from_scale_rotation_translation(scale, rotation, translation)
}

pub fn instanced_scene(seed: u64) -> SceneDesc {
    let mut rng = SplitMix64::new(seed);
    let mut scene = SceneDesc {
        meshes: vec![
            torus(1.0, 0.3, 32, 16),
            cube(),
            quad(),
            Mesh { name: "empty".into(), ..Default::default() },
        ],
        ..Default::default()
    };
    for i in 0..9u32 {
        scene.instances.push(Instance {
            mesh: i % 4,
            material: 10 + i,
            transform: random_transform(&mut rng, i == 4),
        });
    }
    scene
}

// ---------------------------------------------------------------- comparison

/// A CPU traversal the GPU is compared with: obvhs's CWBVH ([`SceneBvh`]) or BVH2 ([`SceneBvh2`]).
pub trait Reference {
    fn closest(&self, ray: &RayQuery) -> Hit;
    fn any(&self, ray: &RayQuery) -> bool;
    fn instances(&self) -> &[InstanceTransforms];
}

/// [`Reference`] for a CPU BVH with `trace_closest`, `trace_any` and `instances` (the bench's
/// BVH2 test uses it too, so the paths are the crate root's).
#[macro_export]
macro_rules! reference {
    ($bvh:ty) => {
        impl $crate::traversal_common::Reference for $bvh {
            fn closest(&self, r: &render::bvh::RayQuery) -> render::bvh::Hit {
                self.trace_closest(r.origin, r.direction, r.t_max)
            }
            fn any(&self, r: &render::bvh::RayQuery) -> bool {
                self.trace_any(r.origin, r.direction, r.t_max)
            }
            fn instances(&self) -> &[render::bvh::InstanceTransforms] {
                &self.instances
            }
        }
    };
}
reference!(SceneBvh);

pub fn rays_for(scene: &SceneDesc, bvh: &SceneBvh, seed: u64) -> Vec<RayQuery> {
    let bounds = bvh.bounds();
    let mut rays = random_rays(bounds, RAYS, 1e30, seed);
    let mut rng = SplitMix64::new(seed ^ 0x5eed);
    let diagonal = (bounds.1 - bounds.0).length();
    for (i, r) in rays.iter_mut().enumerate() {
        // Half the rays aim at a random point of a random triangle (so that many hit), with an
        // unnormalised direction of random length (t is in units of the direction).
        if i % 2 == 0 {
            let instance = &bvh.instances[(rng.next_u64() % bvh.instances.len() as u64) as usize];
            let mesh = &scene.meshes[instance.mesh as usize];
            if !mesh.indices.is_empty() {
                let tri = mesh.indices[(rng.next_u64() % mesh.indices.len() as u64) as usize]
                    .map(|k| mesh.positions[k as usize]);
                let (mut u, mut v) = (rng.next_f32(), rng.next_f32());
                if u + v > 1.0 {
                    (u, v) = (1.0 - u, 1.0 - v);
                }
                let target = instance
                    .object_to_world
                    .transform_point3(tri[0] + u * (tri[1] - tri[0]) + v * (tri[2] - tri[0]));
                r.direction = (target - r.origin) * rng.range(0.2, 3.0);
            }
        }
        // A third of the rays get a finite t_max (shadow-ray style), within the scene's size.
        if i % 3 == 1 {
            r.t_max = rng.range(0.0, diagonal) / r.direction.length();
        }
    }
    rays
}

pub fn relative_difference(a: f32, b: f32) -> f32 {
    (a - b).abs() / a.abs().max(b.abs()).max(1e-6)
}

/// t of the ray against one triangle of one instance, through the same transform and test.
pub fn triangle_t(
    scene: &SceneDesc,
    bvh: &impl Reference,
    ray: &RayQuery,
    instance: u32,
    primitive: u32,
) -> Option<f32> {
    let inst = &bvh.instances()[instance as usize];
    let mesh = &scene.meshes[inst.mesh as usize];
    let o = inst.world_to_object.transform_point3(ray.origin);
    let d = inst.world_to_object.transform_vector3(ray.direction);
    let [a, b, c] = mesh.indices[primitive as usize].map(|i| mesh.positions[i as usize]);
    intersect_triangle(&WatertightRay::new(o, d), a, b, c, ray.t_max).map(|(t, _)| t)
}

/// |cos| of the angle between the ray and the triangle's plane normal, in object space (where
/// the intersection is computed): near 0 the hit distance is ill-conditioned.
pub fn grazing_cosine(
    scene: &SceneDesc,
    bvh: &impl Reference,
    ray: &RayQuery,
    instance: u32,
    primitive: u32,
) -> f32 {
    let inst = &bvh.instances()[instance as usize];
    let mesh = &scene.meshes[inst.mesh as usize];
    let d = inst.world_to_object.transform_vector3(ray.direction);
    let [a, b, c] = mesh.indices[primitive as usize].map(|i| mesh.positions[i as usize]);
    (b - a).cross(c - a).normalize().dot(d.normalize()).abs()
}

/// Closest hit by testing every triangle of every instance (no BVH).
pub fn brute_force(scene: &SceneDesc, bvh: &impl Reference, ray: &RayQuery) -> Hit {
    let mut best = Hit::miss(ray.t_max);
    for (i, inst) in bvh.instances().iter().enumerate() {
        let mesh = &scene.meshes[inst.mesh as usize];
        let o = inst.world_to_object.transform_point3(ray.origin);
        let d = inst.world_to_object.transform_vector3(ray.direction);
        let tri_ray = WatertightRay::new(o, d);
        for (p, idx) in mesh.indices.iter().enumerate() {
            let [a, b, c] = idx.map(|k| mesh.positions[k as usize]);
            if let Some((t, uv)) = intersect_triangle(&tri_ray, a, b, c, best.t) {
                best = Hit { t, instance: i as u32, primitive: p as u32, barycentrics: uv };
            }
        }
    }
    best
}

#[derive(Debug, Default)]
pub struct Agreement {
    rays: usize,
    hits: usize,
    same: usize,
    /// Different triangles at the same t (shared edges, coplanar overlap), each confirmed on the CPU.
    ties: usize,
    /// obvhs culls node boxes that end before t = 1e-4; the WGSL does not.
    near_origin: usize,
    /// Same triangle hit at a grazing angle (|cos| < 1e-3), where t is ill-conditioned.
    grazing: usize,
    failures: Vec<String>,
}

pub fn compare(
    label: &str,
    scene: &SceneDesc,
    bvh: &impl Reference,
    rays: &[RayQuery],
    gpu_hits: &[Hit],
    gpu_any: &[bool],
) -> Agreement {
    let mut a = Agreement { rays: rays.len(), ..Default::default() };
    for (i, ray) in rays.iter().enumerate() {
        let cpu = bvh.closest(ray);
        let cpu_any = bvh.any(ray);
        let gpu = gpu_hits[i];
        a.hits += cpu.is_hit() as usize;
        if cpu_any != cpu.is_hit() {
            a.failures.push(format!(
                "{label} ray {i}: CPU trace_any {cpu_any} but trace_closest {cpu:?}"
            ));
        }
        let near = gpu.t.min(cpu.t) < 1e-4;
        if gpu_any[i] != cpu_any && !near {
            a.failures.push(format!(
                "{label} ray {i} {ray:?}: GPU trace_any {} vs CPU {cpu_any}",
                gpu_any[i]
            ));
        }
        if gpu_any[i] != gpu.is_hit() {
            a.failures.push(format!(
                "{label} ray {i}: GPU trace_any {} but trace_closest {gpu:?}",
                gpu_any[i]
            ));
        }
        if gpu.instance == cpu.instance && gpu.primitive == cpu.primitive {
            if cpu.is_hit() {
                // Rounding differences (fused multiply-adds) in the object-space ray are
                // amplified by 1/|cos| in t and in the barycentrics.
                let cos = grazing_cosine(scene, bvh, ray, cpu.instance, cpu.primitive);
                let t_ok = relative_difference(gpu.t, cpu.t) <= 1e-4;
                let uv_ok = (gpu.barycentrics - cpu.barycentrics).abs().max_element()
                    <= (1e-5 / cos).max(1e-3);
                if cos < 1e-3 && !(t_ok && uv_ok) {
                    a.grazing += 1;
                    continue;
                }
                if !(t_ok && uv_ok) {
                    a.failures.push(format!("{label} ray {i} {ray:?}: same triangle, GPU {gpu:?} vs CPU {cpu:?}, |cos| {cos}"));
                    continue;
                }
            }
            a.same += 1;
        } else if near {
            a.near_origin += 1;
        } else if gpu.is_hit()
            && cpu.is_hit()
            && relative_difference(gpu.t, cpu.t) <= 1e-4
            && triangle_t(scene, bvh, ray, gpu.instance, gpu.primitive)
                .is_some_and(|t| relative_difference(t, cpu.t) <= 1e-4)
        {
            a.ties += 1;
        } else {
            a.failures.push(format!("{label} ray {i} {ray:?}: GPU {gpu:?} vs CPU {cpu:?}"));
        }
    }
    a
}

pub fn check(label: &str, a: &Agreement) {
    println!("{label}: {a:?}");
    assert!(
        a.failures.is_empty(),
        "{label}: {} of {} rays disagree:\n{}",
        a.failures.len(),
        a.rays,
        a.failures.iter().take(10).cloned().collect::<Vec<_>>().join("\n")
    );
    assert!(
        a.ties + a.near_origin + a.grazing <= a.rays / 100,
        "{label}: too many ties/near-origin/grazing hits: {a:?}"
    );
    // The rays must exercise both outcomes for the comparison to mean anything.
    assert!(
        a.hits > a.rays / 5 && a.hits < a.rays * 19 / 20,
        "{label}: {} hits of {} rays",
        a.hits,
        a.rays
    );
}

/// The CPU reference equals brute force on a subset of the rays.
pub fn cpu_matches_brute_force(
    label: &str,
    scene: &SceneDesc,
    bvh: &impl Reference,
    rays: &[RayQuery],
) {
    for (i, ray) in rays.iter().enumerate().step_by(10) {
        let fast = bvh.closest(ray);
        let slow = brute_force(scene, bvh, ray);
        let same = (fast.instance, fast.primitive) == (slow.instance, slow.primitive);
        let tie = fast.is_hit() && slow.is_hit() && relative_difference(fast.t, slow.t) <= 1e-5;
        let near = fast.t.min(slow.t) < 1e-4;
        assert!(same || tie || near, "{label} ray {i}: BVH {fast:?} vs brute force {slow:?}");
    }
}
