//! The WGSL two-level CWBVH traversal (scene_geometry.wgsl) against obvhs's CPU traversal of the
//! same BVHs, on seeded random rays over (a) a mesh loaded from a glTF file, (b) a hairball of
//! thin geometry, (c) several instances with rotations and non-uniform (one mirrored) scales,
//! before and after they move. The CPU reference itself is checked against brute force. The
//! BVH2 traversal (bvh2_traversal.wgsl) is checked the same way against obvhs's BVH2 traversal.

use std::path::{Path, PathBuf};

use glam::{Mat3, Mat4, Quat, Vec2, Vec3};
use render::bvh::{
    Bvh2Geometry, Bvh2Traversal, Hit, InstanceTransforms, InstanceUpdate, RayBatch, RayQuery,
    SceneBvh, SceneBvh2, SceneGeometry, SplitMix64, TraceKind, WatertightRay, intersect_triangle,
    random_rays,
};
use render::gpu::Gpu;
use render::scene::{Instance, Mesh, SceneDesc};

const RAYS: usize = 3000;

fn gpu() -> Gpu {
    Gpu::new().expect("a wgpu adapter (lavapipe on CI)")
}

// ---------------------------------------------------------------- scenes

fn torus(major: f32, minor: f32, rings: u32, sides: u32) -> Mesh {
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
fn write_gltf(dir: &Path, mesh: &Mesh, rotation: Quat, scale: Vec3, translation: Vec3) -> PathBuf {
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
fn load_gltf(path: &Path) -> SceneDesc {
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
fn hairball(strands: u32, segments: u32, radius: f32, seed: u64) -> Mesh {
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

fn cube() -> Mesh {
    let p: Vec<Vec3> = (0..8)
        .map(|i| Vec3::new((i & 1) as f32, ((i >> 1) & 1) as f32, ((i >> 2) & 1) as f32) - 0.5)
        .collect();
    let quads =
        [[0, 2, 3, 1], [4, 5, 7, 6], [0, 1, 5, 4], [2, 6, 7, 3], [0, 4, 6, 2], [1, 3, 7, 5]];
    let indices = quads.iter().flat_map(|q| [[q[0], q[1], q[2]], [q[0], q[2], q[3]]]).collect();
    Mesh { name: "cube".into(), positions: p, normals: Vec::new(), uvs: Vec::new(), indices }
}

fn quad() -> Mesh {
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

fn random_transform(rng: &mut SplitMix64, mirrored: bool) -> Mat4 {
    let rotation = Quat::from_axis_angle(rng.unit_vector(), rng.range(0.0, std::f32::consts::TAU));
    let mut scale = Vec3::new(rng.range(0.3, 2.0), rng.range(0.3, 2.0), rng.range(0.3, 2.0));
    if mirrored {
        scale.x = -scale.x;
    }
    let translation = Vec3::new(rng.range(-3.0, 3.0), rng.range(-3.0, 3.0), rng.range(-3.0, 3.0));
    Mat4::from_scale_rotation_translation(scale, rotation, translation)
}

fn instanced_scene(seed: u64) -> SceneDesc {
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
trait Reference {
    fn closest(&self, ray: &RayQuery) -> Hit;
    fn any(&self, ray: &RayQuery) -> bool;
    fn instances(&self) -> &[InstanceTransforms];
}

macro_rules! reference {
    ($bvh:ty) => {
        impl Reference for $bvh {
            fn closest(&self, r: &RayQuery) -> Hit {
                self.trace_closest(r.origin, r.direction, r.t_max)
            }
            fn any(&self, r: &RayQuery) -> bool {
                self.trace_any(r.origin, r.direction, r.t_max)
            }
            fn instances(&self) -> &[InstanceTransforms] {
                &self.instances
            }
        }
    };
}
reference!(SceneBvh);
reference!(SceneBvh2);

fn rays_for(scene: &SceneDesc, bvh: &SceneBvh, seed: u64) -> Vec<RayQuery> {
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

fn relative_difference(a: f32, b: f32) -> f32 {
    (a - b).abs() / a.abs().max(b.abs()).max(1e-6)
}

/// t of the ray against one triangle of one instance, through the same transform and test.
fn triangle_t(
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
fn grazing_cosine(
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
fn brute_force(scene: &SceneDesc, bvh: &impl Reference, ray: &RayQuery) -> Hit {
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
struct Agreement {
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

fn compare(
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

fn check(label: &str, a: &Agreement) {
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

/// Traces `rays` on the GPU (closest + any) and checks them against the CPU; returns the GPU hits.
fn gpu_matches_cpu(
    label: &str,
    gpu: &Gpu,
    scene: &SceneDesc,
    geometry: &SceneGeometry,
    rays: &[RayQuery],
) -> Vec<Hit> {
    let batch = RayBatch::new(gpu, geometry);
    let hits = batch.trace_closest(gpu, geometry, rays).unwrap();
    let any = batch.trace_any(gpu, geometry, rays).unwrap();
    check(label, &compare(label, scene, geometry.cpu(), rays, &hits, &any));
    hits
}

/// The CPU reference equals brute force on a subset of the rays.
fn cpu_matches_brute_force(
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

// ---------------------------------------------------------------- tests

#[test]
fn gltf_mesh_gpu_traversal_matches_obvhs() {
    let dir = std::env::temp_dir().join(format!("flicker-traversal-{}", std::process::id()));
    let path = write_gltf(
        &dir,
        &torus(1.0, 0.35, 48, 24),
        Quat::from_rotation_x(0.7) * Quat::from_rotation_z(0.3),
        Vec3::new(1.5, 0.6, 1.0),
        Vec3::new(0.2, -0.1, 0.3),
    );
    let scene = load_gltf(&path);
    std::fs::remove_dir_all(&dir).ok();
    assert_eq!(scene.meshes.len(), 1);
    assert_eq!(scene.meshes[0].indices.len(), 48 * 24 * 2);
    let gpu = gpu();
    let geometry = SceneGeometry::new(&gpu, &scene).unwrap();
    let rays = rays_for(&scene, geometry.cpu(), 1);
    cpu_matches_brute_force("glTF torus", &scene, geometry.cpu(), &rays);
    gpu_matches_cpu("glTF torus", &gpu, &scene, &geometry, &rays);
}

#[test]
fn hairball_gpu_traversal_matches_obvhs() {
    let mesh = hairball(400, 8, 0.006, 2);
    let scene = SceneDesc {
        meshes: vec![mesh],
        instances: vec![Instance { mesh: 0, material: 0, transform: Mat4::IDENTITY }],
        ..Default::default()
    };
    let gpu = gpu();
    let geometry = SceneGeometry::new(&gpu, &scene).unwrap();
    let rays = rays_for(&scene, geometry.cpu(), 2);
    cpu_matches_brute_force("hairball", &scene, geometry.cpu(), &rays[..RAYS / 3]);
    gpu_matches_cpu("hairball", &gpu, &scene, &geometry, &rays);
}

#[test]
fn transformed_instances_gpu_traversal_and_surface_points_match_cpu() {
    let scene = instanced_scene(3);
    let gpu = gpu();
    let mut geometry = SceneGeometry::new(&gpu, &scene).unwrap();
    let rays = rays_for(&scene, geometry.cpu(), 3);
    cpu_matches_brute_force("instances", &scene, geometry.cpu(), &rays);
    gpu_matches_cpu("instances", &gpu, &scene, &geometry, &rays);

    // Move every instance: the TLAS is rebuilt, the old transforms become the previous ones.
    let old = scene.clone();
    let mut moved = scene.clone();
    let mut rng = SplitMix64::new(33);
    for (i, inst) in moved.instances.iter_mut().enumerate() {
        inst.transform = random_transform(&mut rng, i == 4);
    }
    assert_eq!(
        geometry.try_update_instances(&gpu, &moved.instances).unwrap(),
        InstanceUpdate::Rebuilt
    );
    let rays = rays_for(&moved, geometry.cpu(), 4);
    let hits = gpu_matches_cpu("moved instances", &gpu, &moved, &geometry, &rays);
    check_surface_points(&gpu, &geometry, &moved, &old, &rays, &hits);

    // Nothing moves: first the previous transforms catch up, then there is nothing to do.
    assert_eq!(
        geometry.try_update_instances(&gpu, &moved.instances).unwrap(),
        InstanceUpdate::TableOnly
    );
    assert_eq!(
        geometry.try_update_instances(&gpu, &moved.instances).unwrap(),
        InstanceUpdate::Unchanged
    );
    let (lo, hi) = geometry.bounds();
    assert!(lo.cmplt(hi).all(), "bounds {lo} {hi}");

    // More instances than the buffers were made for: they grow and traversal still agrees.
    let mut more = moved.clone();
    for i in 0..40u32 {
        more.instances.push(Instance {
            mesh: i % 3,
            material: i,
            transform: random_transform(&mut rng, i % 5 == 0),
        });
    }
    assert_eq!(
        geometry.try_update_instances(&gpu, &more.instances).unwrap(),
        InstanceUpdate::Rebuilt
    );
    let rays = rays_for(&more, geometry.cpu(), 5);
    gpu_matches_cpu("grown instances", &gpu, &more, &geometry, &rays);
}

/// surface_point, previous_world_position and triangle_world_vertices against the same
/// quantities computed here from the scene description.
fn check_surface_points(
    gpu: &Gpu,
    geometry: &SceneGeometry,
    scene: &SceneDesc,
    previous: &SceneDesc,
    rays: &[RayQuery],
    hits: &[Hit],
) {
    let batch = RayBatch::new(gpu, geometry);
    let buffers = batch.upload(gpu, rays).unwrap();
    batch.dispatch(gpu, geometry, &buffers, TraceKind::Closest).unwrap();
    batch.dispatch(gpu, geometry, &buffers, TraceKind::SurfacePoints).unwrap();
    let points = batch.read_surface_points(gpu, &buffers).unwrap();
    let close = |a: Vec3, b: Vec3, tol: f32| (a - b).length() <= tol * (1.0 + b.length());
    let mut checked = 0;
    for ((ray, hit), p) in rays.iter().zip(hits).zip(&points) {
        if !hit.is_hit() {
            continue;
        }
        checked += 1;
        let inst = &scene.instances[hit.instance as usize];
        let mesh = &scene.meshes[inst.mesh as usize];
        let idx = mesh.indices[hit.primitive as usize];
        let [v0, v1, v2] = idx.map(|i| mesh.positions[i as usize]);
        let w = Vec3::new(
            1.0 - hit.barycentrics.x - hit.barycentrics.y,
            hit.barycentrics.x,
            hit.barycentrics.y,
        );
        let object = w.x * v0 + w.y * v1 + w.z * v2;
        let world = inst.transform.transform_point3(object);
        assert!(close(p.position, world, 1e-4), "position {} vs {world}", p.position);
        assert!(
            close(p.position, ray.origin + hit.t * ray.direction, 1e-3),
            "position {} vs ray at t {}",
            p.position,
            hit.t
        );
        let normal_matrix = Mat3::from_mat4(inst.transform).inverse().transpose();
        let geometric = (normal_matrix * (v1 - v0).cross(v2 - v0)).normalize();
        assert!(
            close(p.geometric_normal, geometric, 1e-4),
            "geometric normal {} vs {geometric}",
            p.geometric_normal
        );
        let shading = if mesh.normals.is_empty() {
            geometric
        } else {
            let [n0, n1, n2] = idx.map(|i| mesh.normals[i as usize]);
            (normal_matrix * (w.x * n0 + w.y * n1 + w.z * n2)).normalize()
        };
        assert!(
            close(p.shading_normal, shading, 1e-4),
            "shading normal {} vs {shading}",
            p.shading_normal
        );
        let uv = if mesh.uvs.is_empty() {
            Vec2::ZERO
        } else {
            idx.iter().zip(w.to_array()).map(|(&i, wk)| wk * mesh.uvs[i as usize]).sum()
        };
        assert!((p.uv - uv).abs().max_element() < 1e-4, "uv {} vs {uv}", p.uv);
        assert_eq!(p.material, inst.material);
        let before = previous.instances[hit.instance as usize].transform.transform_point3(object);
        assert!(
            close(p.previous_position, before, 1e-4),
            "previous position {} vs {before}",
            p.previous_position
        );
        for (k, v) in [v0, v1, v2].into_iter().enumerate() {
            assert!(
                close(p.triangle[k], inst.transform.transform_point3(v), 1e-4),
                "triangle vertex {k}"
            );
        }
    }
    assert!(checked > 100, "only {checked} hits to check");
}

#[test]
fn empty_scene_and_bad_input() {
    let gpu = gpu();
    let empty = SceneDesc::default();
    let geometry = SceneGeometry::new(&gpu, &empty).unwrap();
    let rays = vec![RayQuery { origin: Vec3::ZERO, direction: Vec3::X, t_max: 1e30 }];
    let batch = RayBatch::new(&gpu, &geometry);
    assert!(!batch.trace_closest(&gpu, &geometry, &rays).unwrap()[0].is_hit());
    assert_eq!(geometry.bounds(), (Vec3::ZERO, Vec3::ZERO));
    // The batch's stack was sized for the empty scene: it refuses a deeper BVH.
    let deep = SceneDesc {
        meshes: vec![render::bvh::displaced_sphere(20_000, 1)],
        instances: vec![Instance { mesh: 0, material: 0, transform: Mat4::IDENTITY }],
        ..Default::default()
    };
    let deep = SceneGeometry::new(&gpu, &deep).unwrap();
    assert!(
        deep.stack_entries()
            > render::scene_features::SceneFeatures::stack_for(geometry.stack_entries()),
        "{} entries",
        deep.stack_entries()
    );
    let err = batch
        .trace_closest(&gpu, &deep, &rays)
        .err()
        .expect("a deeper BVH than the stack holds is refused")
        .to_string();
    assert!(err.contains("build a new batch"), "{err}");
    assert!(RayBatch::new(&gpu, &deep).trace_closest(&gpu, &deep, &rays).is_ok());

    let mut bad = SceneDesc { meshes: vec![cube()], ..Default::default() };
    bad.meshes[0].indices.push([0, 1, 99]);
    let err =
        SceneGeometry::new(&gpu, &bad).err().expect("an index out of range is refused").to_string();
    assert!(err.contains("cube") && err.contains("99"), "{err}");
    let bad = SceneDesc {
        meshes: vec![cube()],
        instances: vec![Instance { mesh: 3, material: 0, transform: Mat4::IDENTITY }],
        ..Default::default()
    };
    let err = SceneGeometry::new(&gpu, &bad).err().expect("a missing mesh is refused").to_string();
    assert!(err.contains("mesh 3"), "{err}");
    let bad = SceneDesc {
        meshes: vec![cube()],
        instances: vec![Instance { mesh: 0, material: 0, transform: Mat4::ZERO }],
        ..Default::default()
    };
    assert!(SceneGeometry::new(&gpu, &bad).is_err(), "a singular transform is refused");
}

/// The WGSL BVH2 traversal against obvhs's BVH2 traversal (itself against brute force) on the
/// traversal tests' scenes and rays (the same seeds): the glTF torus, the hairball, instances
/// with rotations, mirroring and an empty mesh.
#[test]
fn bvh2_gpu_traversal_matches_obvhs_bvh2_and_brute_force() {
    let gpu = gpu();
    let dir = std::env::temp_dir().join(format!("flicker-bvh2-traversal-{}", std::process::id()));
    let path = write_gltf(
        &dir,
        &torus(1.0, 0.35, 48, 24),
        Quat::from_rotation_x(0.7) * Quat::from_rotation_z(0.3),
        Vec3::new(1.5, 0.6, 1.0),
        Vec3::new(0.2, -0.1, 0.3),
    );
    let gltf = load_gltf(&path);
    std::fs::remove_dir_all(&dir).ok();
    let hairball = SceneDesc {
        meshes: vec![hairball(400, 8, 0.006, 2)],
        instances: vec![Instance { mesh: 0, material: 0, transform: Mat4::IDENTITY }],
        ..Default::default()
    };
    let scenes = [
        ("BVH2 glTF torus", gltf, 1),
        ("BVH2 hairball", hairball, 2),
        ("BVH2 instances", instanced_scene(3), 3),
    ];
    for (label, scene, seed) in scenes {
        let geometry = SceneGeometry::new(&gpu, &scene).unwrap();
        let bvh2 = Bvh2Geometry::new(&gpu, &scene, &geometry).unwrap();
        let rays = rays_for(&scene, geometry.cpu(), seed);
        cpu_matches_brute_force(label, &scene, bvh2.cpu(), &rays[..RAYS / 3]);
        let traversal = Bvh2Traversal { geometry: &geometry, bvh2: &bvh2 };
        let batch = RayBatch::new_bvh2(&gpu, &traversal);
        let hits = batch.trace_closest(&gpu, &traversal, &rays).unwrap();
        let any = batch.trace_any(&gpu, &traversal, &rays).unwrap();
        check(label, &compare(label, &scene, bvh2.cpu(), &rays, &hits, &any));
    }
}
