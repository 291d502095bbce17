//! The WGSL two-level CWBVH traversal (scene_geometry.wgsl) against obvhs's CPU traversal of the
//! same BVHs, on seeded random rays over (a) a mesh loaded from a glTF file, (b) a hairball of
//! thin geometry, (c) several instances with rotations and non-uniform (one mirrored) scales,
//! before and after they move. The CPU reference itself is checked against brute force.

mod traversal_common;

use glam::{Mat3, Mat4, Quat, Vec2, Vec3};
use render::bvh::{Hit, InstanceUpdate, RayBatch, RayQuery, SceneGeometry, SplitMix64, TraceKind};
use render::gpu::Gpu;
use render::scene::{Instance, SceneDesc};
use traversal_common::*;

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

#[test]
fn gltf_mesh_gpu_traversal_matches_obvhs() {
    let tmp = tempfile::tempdir().unwrap();
    let dir = tmp.path().to_path_buf();
    let path = write_gltf(
        &dir,
        &torus(1.0, 0.35, 48, 24),
        Quat::from_rotation_x(0.7) * Quat::from_rotation_z(0.3),
        Vec3::new(1.5, 0.6, 1.0),
        Vec3::new(0.2, -0.1, 0.3),
    );
    let scene = load_gltf(&path);
    drop(tmp);
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
        .expect_err("a deeper BVH than the stack holds is refused")
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

/// Geometry far apart builds in every build type (obvhs's debug self-check, with an absolute
/// tolerance of 1e-5, panicked on it): a cube with one vertex pulled out to 2^41, and cubes as
/// instances 2^41 apart, with the BVH's boxes holding their primitives up to f32 rounding
/// (checked in `Blas::build` and `Tlas::build`; a shrunken box is refused, bvh/build.rs).
#[test]
fn far_apart_geometry_builds() {
    use render::bvh::SceneBvh;
    let far = -(2f32.powi(41));
    let at =
        |x: f32| Instance { mesh: 0, material: 0, transform: Mat4::from_translation(Vec3::X * x) };
    let scene = |mesh: render::scene::Mesh, instances: Vec<Instance>| SceneDesc {
        meshes: vec![mesh],
        instances,
        ..Default::default()
    };
    let mut stretched = cube();
    stretched.positions[0].x = far;
    SceneBvh::new(&scene(stretched, vec![at(0.0)])).unwrap_or_else(|e| panic!("{e}"));
    SceneBvh::new(&scene(cube(), vec![at(0.0), at(1.0), at(far)]))
        .unwrap_or_else(|e| panic!("{e}"));
}

/// Flat instances, whose world boxes have no thickness (a floor, a ceiling, a light 5 mm under
/// it, a wall, one turned, a small one, and one 1000 m away), hit near their edges and corners
/// and inside, by rays from other quads' surfaces moved off them as `offset_origin` moves a
/// path's vertex, with t_max unbounded, just past the hit, or 0.1% short of it (a shadow ray to a
/// light), against brute force. The far quad stretches the TLAS's root over 1000 m, so the
/// root's grid origin is far from these rays: without the node test's slack
/// (`sg_intersect_node`) the GPU missed 10 of these hits, all 1e-5 inside the +z edges of the
/// quads near the origin (obvhs's CPU traversal, the same formula, missed them too); with the
/// far quad left out, none of those but 2 on the small quad, hit from 180 of its sizes away.
#[test]
fn flat_instances_are_entered_by_every_ray_that_hits_them() {
    use std::f32::consts::{FRAC_PI_2, PI};
    let quad_at = |t: Vec3, r: Quat, s: Vec3| Instance {
        mesh: 0,
        material: 0,
        transform: Mat4::from_scale_rotation_translation(s, r, t),
    };
    let down = Quat::from_rotation_x(PI);
    let scene = SceneDesc {
        meshes: vec![quad()],
        instances: vec![
            quad_at(Vec3::ZERO, Quat::IDENTITY, Vec3::ONE),
            quad_at(Vec3::new(0.0, 2.0, 0.0), down, Vec3::ONE),
            quad_at(Vec3::new(0.0, 1.995, 0.0), down, Vec3::new(0.25, 1.0, 0.2)),
            quad_at(Vec3::new(-1.0, 1.0, 0.0), Quat::from_rotation_z(-FRAC_PI_2), Vec3::ONE),
            quad_at(
                Vec3::new(0.3, 0.7, -0.2),
                Quat::from_axis_angle(Vec3::new(1.0, 2.0, 3.0).normalize(), 0.7),
                Vec3::new(0.4, 1.0, 0.3),
            ),
            quad_at(Vec3::new(0.1, 0.3, 0.7), Quat::IDENTITY, Vec3::new(0.1, 1.0, 0.1)),
            quad_at(Vec3::new(1000.0, 3.0, -500.0), Quat::IDENTITY, Vec3::splat(5.0)),
        ],
        ..Default::default()
    };
    let gpu = gpu();
    let geometry = SceneGeometry::new(&gpu, &scene).unwrap();
    let bvh = geometry.cpu();
    let mut rng = SplitMix64::new(55);
    // A point of instance i's quad: near an outer edge or corner (a hair inside, so that the
    // object-space tests of the CPU and the GPU agree on it; off the diagonal the quad's two
    // triangles share), or anywhere.
    let point = |i: usize, rng: &mut SplitMix64| {
        let (a, b) = match rng.next_u64() % 3 {
            0 => (1.0 - 1e-5, rng.range(-1.0, 1.0)),
            1 => (1.0 - 1e-5, 1.0 - 3e-5),
            _ => (rng.range(-1.0, 1.0), rng.range(-1.0, 1.0)),
        };
        let (a, b) = if rng.next_u64().is_multiple_of(2) { (a, b) } else { (b, a) };
        let sign = |rng: &mut SplitMix64| if rng.next_u64().is_multiple_of(2) { 1.0 } else { -1.0 };
        let local = Vec3::new(a * sign(rng), 0.0, b * sign(rng));
        let m = bvh.instances[i].object_to_world;
        (m.transform_point3(local), m.transform_vector3(Vec3::Y).normalize())
    };
    let near = scene.instances.len() - 1;
    let mut rays = Vec::with_capacity(RAYS);
    while rays.len() < RAYS {
        let k = rays.len();
        let target_instance = (rng.next_u64() % scene.instances.len() as u64) as usize;
        let (target, target_normal) = point(target_instance, &mut rng);
        // From another quad's surface (the far quad from itself, or a point near it).
        let from = if target_instance == near {
            target + rng.unit_vector() * rng.range(0.5, 20.0)
        } else {
            let mut other = (rng.next_u64() % near as u64) as usize;
            if other == target_instance {
                other = (other + 1) % near;
            }
            let (p, n) = point(other, &mut rng);
            let to = target - p;
            let scale = 1.0e-4 * (1.0 + p.abs().max_element());
            p + n * if to.dot(n) >= 0.0 { scale } else { -scale }
        };
        let t_max = match k % 3 {
            0 => 1e30,
            1 => 1.0 + 1e-5,
            _ => 1.0 - 1e-3,
        };
        // Not grazing the target's plane: a ray within about 1° of a plane meets it (or not)
        // by the rounding of its object-space direction, which the GPU and the CPU round apart
        // (left in, 5 of 3000 rays disagree, e.g. a ceiling hit at |cos| 5e-6 that the GPU
        // finds and the CPU does not).
        if (target - from).normalize().dot(target_normal).abs() < 0.02 {
            continue;
        }
        rays.push(RayQuery { origin: from, direction: target - from, t_max });
    }
    // Against brute force, not obvhs: obvhs's CPU traversal misses some of these hits too.
    struct Brute<'a>(&'a SceneDesc, &'a render::bvh::SceneBvh);
    impl Reference for Brute<'_> {
        fn closest(&self, r: &RayQuery) -> Hit {
            brute_force(self.0, self.1, r)
        }
        fn any(&self, r: &RayQuery) -> bool {
            self.closest(r).is_hit()
        }
        fn instances(&self) -> &[render::bvh::InstanceTransforms] {
            &self.1.instances
        }
    }
    let batch = RayBatch::new(&gpu, &geometry);
    let hits = batch.trace_closest(&gpu, &geometry, &rays).unwrap();
    let any = batch.trace_any(&gpu, &geometry, &rays).unwrap();
    let label = "flat instances";
    check(label, &compare(label, &scene, &Brute(&scene, bvh), &rays, &hits, &any));
}
