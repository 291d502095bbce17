//! Media bounded by a closed mesh (scene::MediumBound): baking empties the voxels whose centres
//! lie outside the mesh. A homogeneous sphere's optical depth through its centre is σ_t · 2r to
//! within the voxel and tessellation resolution, a ray through the box outside the sphere sees
//! T = 1, every voxel away from the surface agrees with the analytic sphere and torus (the
//! shipped OBJ), and the GPU's estimates through a sphere-bounded cloud are the CPU reference's.

use std::path::Path;
use std::sync::OnceLock;

use glam::{UVec3, Vec3};
use media::gpu::{GpuMedium, ImagePass};
use media::image::{ImageKey, directions, estimates, exact, reduce};
use media::regular_tracking::optical_depth;
use media::{DensityGrid, DensityKind, Estimator, Medium};
use render::frame::CameraBasis;
use render::gpu::Gpu;
use render::scene::Camera;
use scene::{MediumBound, MediumDesc};

fn gpu() -> &'static Gpu {
    static GPU: OnceLock<Gpu> = OnceLock::new();
    GPU.get_or_init(|| Gpu::new().expect("a wgpu adapter (lavapipe on CI)"))
}

fn desc(
    kind: DensityKind,
    bound: MediumBound,
    lo: Vec3,
    hi: Vec3,
    res: u32,
    sigma_t: f32,
) -> MediumDesc {
    MediumDesc {
        name: "m".into(),
        kind,
        box_min: lo,
        box_max: hi,
        bound,
        sigma_t,
        resolution: (res, res, res),
        albedo: Vec3::splat(0.8),
        emission: None,
        motion: Default::default(),
        super_voxel: scene::medium::DEFAULT_SUPER_VOXEL,
    }
}

const SEGMENTS: u32 = 64;

/// How far a UV sphere of radius r with `SEGMENTS` lies inside the true sphere at most.
fn tessellation(r: f32) -> f32 {
    r * (1.0 - (std::f32::consts::PI / (SEGMENTS / 2) as f32).cos())
}

#[test]
fn a_homogeneous_sphere_has_optical_depth_sigma_t_2r_through_its_centre_and_none_outside() {
    let sigma_t = 1.5;
    let r = 1.0;
    // An odd resolution puts voxel centres on the sphere's planes of symmetry (rays through
    // its vertices and along its edges in the inside test).
    for res in [48, 49] {
        let medium = Medium::new(DensityGrid::from_desc(&desc(
            DensityKind::Homogeneous,
            MediumBound::Sphere { segments: SEGMENTS },
            Vec3::splat(-r),
            Vec3::splat(r),
            res,
            sigma_t,
        )));
        let h = 2.0 * r / res as f32;
        // A chord through the centre ends in voxels whose centres are inside; its length is off
        // by at most half a voxel diagonal at either end, plus the tessellation.
        let tolerance = 3f32.sqrt() * h + 2.0 * tessellation(r);
        let mut worst = 0.0f32;
        for d in [
            Vec3::X,
            Vec3::Y,
            Vec3::Z,
            Vec3::new(1.0, 1.0, 0.0),
            Vec3::new(1.0, 2.0, 3.0),
            Vec3::new(-0.3, 0.2, 1.0),
        ] {
            let d = d.normalize();
            let seg = medium.segment(-3.0 * d, d, 1e4).expect("the ray crosses the box");
            let length = optical_depth(&medium, &seg) as f32 / sigma_t;
            worst = worst.max((length - 2.0 * r).abs());
            assert!(
                (length - 2.0 * r).abs() <= tolerance,
                "res {res}, direction {d}: chord {length}, expected 2r = {} within {tolerance}",
                2.0 * r
            );
            let t = (-optical_depth(&medium, &seg)).exp() as f32;
            let want = (-sigma_t * 2.0 * r).exp();
            assert!(
                (t / want).ln().abs() <= sigma_t * tolerance,
                "res {res}: T {t} against exp(-σ_t 2r) = {want}"
            );
        }
        println!(
            "res {res}: worst chord error {worst:.4} (tolerance {tolerance:.4}, voxel {h:.4})"
        );
        // Inside the box, outside the sphere: near an edge of the box, ‖p‖ ≥ √(0.9² + 0.9²) > r.
        for origin in [Vec3::new(-1.5, 0.9, 0.9), Vec3::new(0.95, -1.5, -0.92)] {
            let d = if origin.x < -1.0 { Vec3::X } else { Vec3::Y };
            let seg = medium.segment(origin, d, 1e4).expect("the ray crosses the box");
            assert!(seg.length() > 1.9, "the ray runs through the box");
            assert_eq!(
                optical_depth(&medium, &seg),
                0.0,
                "origin {origin}: T = 1 outside the sphere"
            );
            for est in [
                Estimator::RatioTracking,
                Estimator::TrackLength,
                Estimator::Jackknife { samples: 4 },
            ] {
                let e = est.estimate(&medium, &seg, &mut media::Pcg::new(3));
                assert_eq!(e.value, 1.0, "{}: outside the sphere", est.label());
            }
        }
        // Every voxel centre farther than the tessellation's sagitta from the sphere agrees with it.
        let g = &medium.density;
        for z in 0..res {
            for y in 0..res {
                for x in 0..res {
                    let p = (UVec3::new(x, y, z).as_vec3() + 0.5) * h - Vec3::splat(r);
                    let inside = g.at(UVec3::new(x, y, z)) > 0.0;
                    let distance = p.length() - r;
                    if distance.abs() > tessellation(r) + 1e-4 {
                        assert_eq!(
                            inside,
                            distance < 0.0,
                            "res {res}, voxel ({x}, {y}, {z}) at {p}: |p| − r = {distance}"
                        );
                    }
                }
            }
        }
    }
}

#[test]
fn the_shipped_torus_obj_bounds_its_medium_as_the_analytic_torus() {
    let file = Path::new(env!("CARGO_MANIFEST_DIR")).join("../scenarios/assets/torus.obj");
    // The box of scenarios/volume_mesh_bound.ron; the torus (its header): centre (1, 2.5, 1.5),
    // ring radius 0.9, tube 0.4, in the x-z plane.
    let (lo, hi) = (Vec3::new(-0.4, 1.0, 0.1), Vec3::new(2.4, 4.0, 2.9));
    let (centre, ring, tube) = (Vec3::new(1.0, 2.5, 1.5), 0.9f32, 0.4f32);
    let res = 40;
    let grid = DensityGrid::from_desc(&desc(
        DensityKind::Homogeneous,
        MediumBound::Obj { file },
        lo,
        hi,
        res,
        2.0,
    ));
    // 24 x 12 quads lie inside the torus by at most (ring + tube)(1 − cos(π/24)) + tube (1 − cos(π/12)).
    let slack = (ring + tube) * (1.0 - (std::f32::consts::PI / 24.0).cos())
        + tube * (1.0 - (std::f32::consts::PI / 12.0).cos());
    let (mut inside, mut checked) = (0, 0);
    for z in 0..res {
        for y in 0..res {
            for x in 0..res {
                let p =
                    lo + (UVec3::new(x, y, z).as_vec3() + 0.5) / res as f32 * (hi - lo) - centre;
                let distance = (Vec3::new(p.x, 0.0, p.z).length() - ring).hypot(p.y) - tube;
                let got = grid.at(UVec3::new(x, y, z));
                if distance.abs() > slack + 1e-4 {
                    checked += 1;
                    assert_eq!(
                        got > 0.0,
                        distance < 0.0,
                        "voxel ({x}, {y}, {z}): distance to the torus {distance}, μ {got}"
                    );
                }
                inside += usize::from(got > 0.0);
            }
        }
    }
    // Its volume 2π² R r² over the voxel volume.
    let voxels = 2.0 * std::f32::consts::PI.powi(2) * ring * tube * tube
        / ((hi - lo) / res as f32).element_product();
    println!(
        "{inside} voxels inside (the torus holds {voxels:.0}); {checked} checked against the analytic torus"
    );
    assert!(
        (inside as f32 - voxels).abs() < 0.1 * voxels,
        "{inside} voxels inside, the torus holds {voxels:.0}"
    );
}

#[test]
fn gpu_estimates_through_a_sphere_bounded_cloud_are_the_cpu_references() {
    const W: u32 = 32;
    const H: u32 = 18;
    let kind = DensityKind::Cloud { octaves: 4, frequency: 3.0, seed: 7 };
    let medium = Medium::new(DensityGrid::from_desc(&desc(
        kind,
        MediumBound::Sphere { segments: 32 },
        Vec3::new(-1.0, -0.6, -1.0),
        Vec3::new(1.0, 0.6, 1.0),
        32,
        6.0,
    )));
    let camera = Camera {
        position: Vec3::new(0.2, 0.3, -3.0),
        target: Vec3::ZERO,
        up: Vec3::Y,
        vfov: 40f32.to_radians(),
    };
    let cam = CameraBasis::new(&camera, W, H);
    let dirs = directions(&cam, W, H);
    let gm = GpuMedium::new(gpu(), &medium);
    let pass = ImagePass::new(gpu(), &gm).expect("media image pass compiles");
    let key = ImageKey { seed: 4, frame: 1, spp: 4 };
    let reference = exact(&medium, cam.position, &dirs);
    // Rays through the box's corners miss the ellipsoid: T = 1 there, exactly, in every estimate.
    let clear: Vec<usize> = (0..dirs.len())
        .filter(|&p| reference[p] == 1.0 && medium.segment(cam.position, dirs[p], 1e4).is_some())
        .collect();
    assert!(
        !clear.is_empty() && reference.iter().any(|&t| t < 0.5),
        "the image shows the cloud and the box outside it"
    );
    for est in [Estimator::RatioTracking, Estimator::Jackknife { samples: 8 }] {
        let (got, _) = pass.run(gpu(), &gm, cam.position, &dirs, W, est, key).expect("image");
        let want = estimates(&medium, cam.position, &dirs, est, key);
        let differ = got
            .iter()
            .zip(&want)
            .filter(|(g, w)| {
                (g.value - w.value).abs() > 1e-4 + 1e-3 * w.value.abs() || g.lookups != w.lookups
            })
            .count();
        assert!(
            differ * 100 <= got.len(),
            "{}: {differ} of {} estimates differ",
            est.label(),
            got.len()
        );
        let stats = reduce(&got, key.spp);
        for &p in &clear {
            assert_eq!(
                stats.mean[p],
                1.0,
                "{}: pixel {p} passes the box outside the bound",
                est.label()
            );
        }
    }
}
