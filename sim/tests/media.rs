//! Participating media in scenario files: parsed with their defaults, absent by default, and
//! bad declarations refused with the file and the line of the medium.

use std::path::Path;

use scene::DensityKind;
use sim::Scenario;

fn parse(text: &str) -> Result<Scenario, sim::ScenarioError> {
    Scenario::from_ron(text, Path::new("volume.ron"))
}

fn scenario(medium: &str) -> String {
    format!(
        "Scenario(scene: Builtin(\"cornell_box\"), resolution: (32, 18), frames: 1,\n methods: [PathTracing(spp: 1)],\n media: [\n  {medium},\n ])"
    )
}

#[test]
fn a_medium_parses_with_defaults_and_no_media_is_the_default() {
    let s = parse(&scenario(r#"(name: "cloud", kind: Cloud(octaves: 4, frequency: 3.0, seed: 7), box_min: (-1, -1, -1), box_max: (1, 1, 1), sigma_t: 6.0)"#)).unwrap();
    assert_eq!(s.media.len(), 1);
    assert_eq!(s.media[0].kind, DensityKind::Cloud { octaves: 4, frequency: 3.0, seed: 7 });
    assert_eq!(s.media[0].resolution, (64, 64, 64));
    assert_eq!(s.media[0].emission, None);
    let none = parse("Scenario(scene: Builtin(\"cornell_box\"), resolution: (32, 18), frames: 1, methods: [PathTracing(spp: 1)])").unwrap();
    assert!(none.media.is_empty());
    // Nothing about media in the manifest of a scene without them.
    assert!(!serde_json::to_string(&none).unwrap().contains("media"));
}

#[test]
fn bad_media_name_the_file_and_line() {
    let cases = [
        (
            r#"(name: "flat", kind: Homogeneous, box_min: (0, 0, 0), box_max: (1, 0, 1), sigma_t: 1.0)"#,
            "box_min",
        ),
        (
            r#"(name: "neg", kind: Homogeneous, box_min: (0, 0, 0), box_max: (1, 1, 1), sigma_t: -1.0)"#,
            "sigma_t",
        ),
        (
            r#"(name: "big", kind: Homogeneous, box_min: (0, 0, 0), box_max: (1, 1, 1), sigma_t: 1.0, resolution: (0, 8, 8))"#,
            "resolution",
        ),
        (
            r#"(name: "bright", kind: Homogeneous, box_min: (0, 0, 0), box_max: (1, 1, 1), sigma_t: 1.0, albedo: (2, 0, 0))"#,
            "albedo",
        ),
        (
            r#"(name: "x", kind: Smoke, box_min: (0, 0, 0), box_max: (1, 1, 1), sigma_t: 1.0)"#,
            "Smoke",
        ),
        (
            r#"(name: "p", kind: Homogeneous, box_min: (0, 0, 0), box_max: (1, 1, 1), sigma_t: 1.0, motion: (pulse_amplitude: 1.5, pulse_period: 2))"#,
            "pulse_amplitude",
        ),
        (
            r#"(name: "q", kind: Homogeneous, box_min: (0, 0, 0), box_max: (1, 1, 1), sigma_t: 1.0, motion: (pulse_amplitude: 0.5))"#,
            "pulse_period",
        ),
        (
            r#"(name: "r", kind: Homogeneous, box_min: (0, 0, 0), box_max: (1, 1, 1), sigma_t: 1.0, motion: (spin: 3))"#,
            "spin",
        ),
        (
            r#"(name: "s", kind: Homogeneous, box_min: (0, 0, 0), box_max: (1, 1, 1), sigma_t: 1.0, super_voxel: 0)"#,
            "super_voxel 0",
        ),
    ];
    for (medium, word) in cases {
        let e = parse(&scenario(medium)).unwrap_err();
        let text = e.to_string();
        assert!(text.starts_with("volume.ron:4:"), "{text}");
        assert!(text.contains(word), "{text}");
    }
}

#[test]
fn an_animated_medium_moves_scales_spins_and_pulses_in_closed_form() {
    let s = parse(&scenario(
        r#"(name: "m", kind: Homogeneous, box_min: (0, 0, 0), box_max: (2, 2, 2), sigma_t: 2.0,
            motion: (velocity: (1, 0, 0), scale_per_second: 0.5, spin_degrees_per_second: 90, pulse_amplitude: 0.25, pulse_period: 4))"#,
    ))
    .unwrap();
    let m = &s.media[0];
    let a = m.at(1.0);
    // Centre (1, 1, 1) + (1, 0, 0); half size 1 · 1.5; σ 2 (1 + 0.25 sin(π/2)); 90° = π/2.
    assert!(
        (a.box_min - glam::Vec3::new(0.5, -0.5, -0.5)).length() < 1e-6
            && (a.box_max - glam::Vec3::new(3.5, 2.5, 2.5)).length() < 1e-6,
        "{a:?}"
    );
    assert!(
        (a.sigma_t - 2.5).abs() < 1e-6 && (a.spin - std::f32::consts::FRAC_PI_2).abs() < 1e-6,
        "{a:?}"
    );
    // A still medium is its declaration at any time.
    let still = parse(&scenario(
        r#"(name: "s", kind: Homogeneous, box_min: (0, 0, 0), box_max: (1, 1, 1), sigma_t: 1.0)"#,
    ))
    .unwrap();
    let st = still.media[0].at(7.0);
    assert_eq!(
        (st.box_min, st.box_max, st.sigma_t, st.spin),
        (still.media[0].box_min, still.media[0].box_max, 1.0, 0.0)
    );
}

#[test]
fn a_raw_density_grid_loads_relative_to_the_scenario_and_bad_files_name_their_line() {
    let tmp = tempfile::tempdir().unwrap();
    let dir = tmp.path().to_path_buf();
    std::fs::create_dir_all(dir.join("assets")).unwrap();
    let grid =
        |name: &str, text: &str| std::fs::write(dir.join("assets").join(name), text).unwrap();
    grid("ok.density", "# a 2x1x1 grid\ndensity_grid 2 1 1\n0.25\n1\n");
    grid("header.density", "# no header\n0.5 0.5\n");
    grid("value.density", "density_grid 2 1 1\n0.5\n1.5\n");
    grid("short.density", "density_grid 2 2 1\n0.5 0.5\n0.5\n");
    let load = |file: &str| {
        let text = scenario(&format!(
            r#"(name: "g", kind: Grid(file: "assets/{file}"), box_min: (0, 0, 0), box_max: (1, 1, 1), sigma_t: 2.0)"#
        ));
        Scenario::from_ron(&text, &dir.join("volume.ron"))
    };
    let s = load("ok.density").unwrap();
    let DensityKind::Grid { file } = &s.media[0].kind else { panic!("{:?}", s.media[0].kind) };
    assert_eq!(
        scene::RawGrid::load(file).unwrap(),
        scene::RawGrid { res: (2, 1, 1), data: vec![0.25, 1.0] }
    );
    for (file, line, word) in [
        ("header.density", 2, "density_grid NX NY NZ"),
        ("value.density", 3, "'1.5'"),
        ("short.density", 3, "3 values; expected 2x2x1 = 4"),
    ] {
        let e = load(file).unwrap_err().to_string();
        assert!(e.contains(&format!("{file}:{line}:")) && e.contains(word), "{e}");
        assert!(e.contains("volume.ron:4:"), "{e}");
    }
    assert!(load("missing.density").unwrap_err().to_string().contains("cannot read"));
    // The shipped grid parses.
    let shipped = scene::RawGrid::load(
        &Path::new(env!("CARGO_MANIFEST_DIR")).join("../scenarios/assets/smoke_ring.density"),
    )
    .unwrap();
    assert_eq!(shipped.res, (16, 16, 16));
}

#[test]
fn a_mesh_bound_loads_relative_to_the_scenario_and_bad_meshes_name_their_line() {
    let tmp = tempfile::tempdir().unwrap();
    let dir = tmp.path().to_path_buf();
    std::fs::create_dir_all(dir.join("assets")).unwrap();
    let obj = |name: &str, text: &str| std::fs::write(dir.join("assets").join(name), text).unwrap();
    // An octahedron, outward-facing; variants with one face missing, one flipped, a bad index.
    let vertices = "v 1 0 0\nv -1 0 0\nv 0 1 0\nv 0 -1 0\nv 0 0 1\nv 0 0 -1\n";
    let faces =
        ["f 1 3 5", "f 3 2 5", "f 2 4 5", "f 4 1 5", "f 3 1 6", "f 2 3 6", "f 4 2 6", "f 1 4 6"];
    obj("ok.obj", &format!("# octahedron\n{vertices}{}\n", faces.join("\n")));
    obj("open.obj", &format!("{vertices}{}\n", faces[..7].join("\n")));
    obj("flipped.obj", &format!("{vertices}{}\nf 5 3 1\n", faces[1..].join("\n")));
    obj("index.obj", &format!("{vertices}f 1 3 7\n"));
    obj("vertex.obj", "v 1 0\n");
    let load = |bound: &str| {
        let text = scenario(&format!(
            r#"(name: "m", kind: Homogeneous, box_min: (-1, -1, -1), box_max: (1, 1, 1), bound: {bound}, sigma_t: 2.0)"#
        ));
        Scenario::from_ron(&text, &dir.join("volume.ron"))
    };
    let s = load(r#"Obj(file: "assets/ok.obj")"#).unwrap();
    let mesh = s.media[0].bound.mesh(s.media[0].box_min, s.media[0].box_max).unwrap().unwrap();
    assert_eq!(mesh.triangles.len(), 8);
    // In the box's unit coordinates.
    assert_eq!(mesh.positions[0], glam::Vec3::new(1.0, 0.5, 0.5));
    for (file, line, word) in [
        // The first face (in file order) with an open edge: the one beside the missing face.
        ("open.obj", 10, "no face on its other side"),
        ("flipped.obj", 14, "same direction"),
        ("index.obj", 7, "'7'; expected a vertex index 1 to 6"),
        ("vertex.obj", 1, "expected a vertex 'v X Y Z'"),
    ] {
        let e = load(&format!(r#"Obj(file: "assets/{file}")"#)).unwrap_err().to_string();
        assert!(e.contains(&format!("{file}:{line}:")) && e.contains(word), "{e}");
        assert!(e.contains("volume.ron:4:"), "{e}");
    }
    assert!(
        load(r#"Obj(file: "assets/missing.obj")"#)
            .unwrap_err()
            .to_string()
            .contains("cannot read the OBJ mesh")
    );
    assert!(
        load("Sphere(segments: 7)")
            .unwrap_err()
            .to_string()
            .contains("expected an even number from 4 to 256")
    );
    assert_eq!(
        load("Sphere(segments: 16)").unwrap().media[0].bound,
        scene::MediumBound::Sphere { segments: 16 }
    );
    // The shipped torus is closed.
    let torus = scene::ClosedMesh::load_obj(
        &Path::new(env!("CARGO_MANIFEST_DIR")).join("../scenarios/assets/torus.obj"),
    )
    .unwrap();
    assert_eq!(torus.triangles.len(), 2 * 24 * 12);
}

#[test]
fn a_medium_without_a_bound_keeps_its_debug_form() {
    // The reference cache keys a medium by its Debug form: the bound appears only when set.
    let s = parse(&scenario(
        r#"(name: "b", kind: Homogeneous, box_min: (0, 0, 0), box_max: (1, 1, 1), sigma_t: 1.0)"#,
    ))
    .unwrap();
    assert_eq!(
        format!("{:?}", s.media[0]),
        "MediumDesc { name: \"b\", kind: Homogeneous, box_min: Vec3(0.0, 0.0, 0.0), box_max: Vec3(1.0, 1.0, 1.0), sigma_t: 1.0, resolution: (64, 64, 64), albedo: Vec3(0.8, 0.8, 0.8), emission: None, motion: MediumMotion { velocity: Vec3(0.0, 0.0, 0.0), scale_per_second: 0.0, spin_degrees_per_second: 0.0, pulse_amplitude: 0.0, pulse_period: 0.0 } }"
    );
    let b = parse(&scenario(r#"(name: "b", kind: Homogeneous, box_min: (0, 0, 0), box_max: (1, 1, 1), bound: Sphere(segments: 8), sigma_t: 1.0)"#)).unwrap();
    assert!(format!("{:?}", b.media[0]).contains("bound: Sphere { segments: 8 }"));
    // So does the super-voxel edge: only when it is not the default 16.
    assert!(!format!("{:?}", s.media[0]).contains("super_voxel"));
    let c = parse(&scenario(r#"(name: "c", kind: Homogeneous, box_min: (0, 0, 0), box_max: (1, 1, 1), sigma_t: 1.0, super_voxel: 12)"#)).unwrap();
    assert_eq!(c.media[0].super_voxel, 12);
    assert!(format!("{:?}", c.media[0]).ends_with("super_voxel: 12 }"));
}
