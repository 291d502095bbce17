//! Scenario files and simulations: every shipped scenario plays; errors point at the file;
//! animations and events do what they say, deterministically.

use std::path::{Path, PathBuf};

use glam::{Quat, Vec3};
use scene::{Light, SceneChanges, SceneDesc};
use sim::{ReferenceFrames, ReferenceSpec, Scenario, SimError, Simulation};

fn scenarios_dir() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../scenarios")
}

fn parse(text: &str) -> Scenario {
    Scenario::from_ron(text, &scenarios_dir().join("inline.ron")).unwrap_or_else(|e| panic!("{e}"))
}

fn with(scene: &str, extra: &str) -> Scenario {
    parse(&format!(
        "Scenario(scene: Builtin(\"{scene}\"), resolution: (32, 18), frames: 60, time_step: 0.1, seed: 3,\n methods: [PathTracing(spp: 1)],\n{extra})"
    ))
}

fn sun_direction(scene: &SceneDesc) -> Vec3 {
    scene
        .lights
        .iter()
        .find_map(|l| match l {
            Light::Directional { direction, .. } => Some(*direction),
            _ => None,
        })
        .expect("a directional light")
}

fn point_intensity(scene: &SceneDesc) -> Vec3 {
    scene
        .lights
        .iter()
        .find_map(|l| match l {
            Light::Point { intensity, .. } => Some(*intensity),
            _ => None,
        })
        .expect("a point light")
}

#[test]
fn every_shipped_scenario_loads_and_plays() {
    let mut files: Vec<PathBuf> = std::fs::read_dir(scenarios_dir())
        .unwrap()
        .map(|e| e.unwrap().path())
        .filter(|p| p.extension().is_some_and(|x| x == "ron"))
        .collect();
    files.sort();
    let required = [
        "cornell_box",
        "corridor",
        "door_gap",
        "courtyard",
        "hairball",
        "rotating_cone",
        "flash_sine",
        "flash_square",
        "strobe",
        "boids",
        "keyframes",
        "camera_path",
        "events",
        "sss_flash",
        "sss_toggle",
        "sss_boids",
    ];
    for r in required {
        assert!(files.iter().any(|f| f.file_stem().unwrap() == r), "scenarios/{r}.ron is missing");
    }
    for f in &files {
        let scenario = Scenario::load(f).unwrap_or_else(|e| panic!("{e}"));
        assert!(
            scenario.resolution.0 * scenario.resolution.1 <= 160 * 90,
            "{}: too big for CI",
            f.display()
        );
        // References are cached by scene content, so a still scene renders only a few: 1024 spp
        // at 64x36 (a dark corridor needs it) takes minutes on lavapipe. More samples only on a
        // smaller image, within that many paths a frame (Fig. 7's 2048 spp at 32x18 is half).
        let reference_paths = scenario.resolution.0 as u64
            * scenario.resolution.1 as u64
            * scenario.reference.spp as u64;
        assert!(
            scenario.frames <= 60
                && (scenario.reference.spp <= 1024 || reference_paths <= 64 * 36 * 1024),
            "{}: too long for CI",
            f.display()
        );
        assert_eq!(scenario.output, Path::new("runs").join(&scenario.name));
        let mut s = Simulation::new(&scenario).unwrap_or_else(|e| panic!("{e}"));
        assert!(
            !s.scene().meshes.is_empty() && !s.scene().instances.is_empty(),
            "{}: empty scene",
            f.display()
        );
        for _ in 0..3 {
            s.step();
        }
        assert_eq!(s.frame(), 3);
    }
}

#[test]
fn ron_syntax_error_reports_line_column_and_expectation() {
    let text = "Scenario(\n    scene: Builtin(\"cornell_box\"),\n    resolution: (32 18),\n)";
    let e = Scenario::from_ron(text, Path::new("scenarios/bad.ron")).unwrap_err();
    assert_eq!(e.position.map(|p| p.0), Some(3), "{e}");
    let s = e.to_string();
    assert!(s.starts_with("scenarios/bad.ron:3:"), "{s}");
    assert!(s.to_lowercase().contains("expected"), "{s}");
}

#[test]
fn unknown_field_is_reported_with_the_expected_ones() {
    let text =
        "Scenario(\n  scene: Builtin(\"cornell_box\"),\n  resolution: (32, 18),\n  frame: 3,\n)";
    let e = Scenario::from_ron(text, Path::new("x.ron")).unwrap_err().to_string();
    assert!(e.starts_with("x.ron:4:"), "{e}");
    assert!(
        e.contains("frame") && e.contains("frames"),
        "should name the field and the expected ones: {e}"
    );
}

#[test]
fn unknown_scene_name_lists_the_builtins() {
    let text = "Scenario(\n  scene: Builtin(\"cornel_box\"),\n  resolution: (32, 18), frames: 1, methods: [PathTracing(spp: 1)])";
    let e = Scenario::from_ron(text, Path::new("typo.ron")).unwrap_err().to_string();
    assert!(e.starts_with("typo.ron:2:"), "{e}");
    assert!(e.contains("unknown scene 'cornel_box'") && e.contains("cornell_box, corridor"), "{e}");
}

#[test]
fn unknown_entity_fails_before_frame_zero_naming_file_and_known_names() {
    let s =
        with("cornell_box", "events: [\n (frame: 5, action: Toggle(entity: \"celing_light\")),\n]");
    let e = Simulation::new(&s).err().expect("unknown entity must fail");
    assert!(matches!(&e, SimError::UnknownName { name, .. } if name == "celing_light"));
    let msg = e.to_string();
    assert!(msg.contains("inline.ron:4:"), "{msg}");
    assert!(
        msg.contains("unknown entity 'celing_light'")
            && msg.contains("ceiling_light")
            && msg.contains("tall_box"),
        "{msg}"
    );

    let s = with(
        "courtyard",
        "animations: [Rotate(entity: \"moon\", axis: (0, 1, 0), degrees_per_second: 1)]",
    );
    assert!(Simulation::new(&s).err().unwrap().to_string().contains("unknown entity 'moon'"));
    let s = with(
        "courtyard",
        "events: [(frame: 1, action: SetMaterial(material: \"gold\", metallic: 1.0))]",
    );
    assert!(
        Simulation::new(&s)
            .err()
            .unwrap()
            .to_string()
            .contains("unknown material 'gold'; expected one of: paving, walls")
    );
    let s = with(
        "courtyard",
        "events: [(frame: 1, action: RotateLight(light: \"ground\", axis: (0, 1, 0), degrees: 3))]",
    );
    assert!(Simulation::new(&s).err().unwrap().to_string().contains("'ground' is not a light"));
}

#[test]
fn bad_values_are_refused() {
    for (extra, what) in [
        ("regions: [(name: \"r\", x: 30, y: 0, w: 8, h: 8)]", "region 'r'"),
        ("time_step: 0.0", "time_step"),
    ] {
        let text = format!(
            "Scenario(scene: Builtin(\"cornell_box\"), resolution: (32, 18), frames: 4, methods: [PathTracing(spp: 1)], {extra})"
        );
        let e = Scenario::from_ron(&text, Path::new("v.ron")).unwrap_err().to_string();
        assert!(e.contains(what) && e.contains("expected"), "{e}");
    }
}

#[test]
fn method_labels_reference_frames_and_summary() {
    let every = ReferenceSpec { spp: 16, frames: ReferenceFrames::Every(10), random_walk: false };
    let wanted: Vec<u32> = (0..30).filter(|&f| every.wants(f, 25)).collect();
    assert_eq!(wanted, vec![0, 10, 20]);
    let list = ReferenceSpec {
        spp: 16,
        frames: ReferenceFrames::List(vec![3, 7, 99]),
        random_walk: false,
    };
    assert_eq!((0..100).filter(|&f| list.wants(f, 50)).collect::<Vec<_>>(), vec![3, 7]);
    assert!(!(0..10).any(|f| ReferenceSpec::default().wants(f, 10)));

    let s = Scenario::load(&scenarios_dir().join("events.ron")).unwrap();
    let summary = s.events_summary();
    assert_eq!(summary[0], (10, "rotate light 'sun' by 30°".to_string()));
    assert_eq!(summary.iter().map(|e| e.0).collect::<Vec<_>>(), vec![10, 20, 30, 40]);
    assert_eq!(s.regions[0].width, 80);
}

#[test]
fn light_rotation_event_turns_the_sun_by_its_angle_at_its_frame() {
    let s = with(
        "courtyard",
        "events: [(frame: 4, action: RotateLight(light: \"sun\", axis: (0, 1, 0), degrees: 30))]",
    );
    let mut sim = Simulation::new(&s).unwrap();
    let before = sun_direction(sim.scene());
    for _ in 0..3 {
        sim.step();
        assert!(!sim.changed(), "nothing moves before the event (frame {})", sim.frame());
    }
    sim.step();
    assert_eq!(sim.frame(), 4);
    assert!(sim.changed());
    let after = sun_direction(sim.scene());
    let expected = Quat::from_rotation_y(30f32.to_radians()) * before;
    assert!((after - expected).length() < 1e-5, "{after} vs {expected}");
    let flat = |v: Vec3| Vec3::new(v.x, 0.0, v.z).normalize();
    assert!((flat(before).angle_between(flat(after)).to_degrees() - 30.0).abs() < 1e-3);
    sim.step();
    assert!(!sim.changed());
}

#[test]
fn one_shot_rotation_applies_once_and_continuous_rotation_accumulates() {
    let s = with(
        "rotating_cone",
        "animations: [RotateOnce(entity: \"cone\", axis: (0, 1, 0), degrees: 90, frame: 2)]",
    );
    let mut sim = Simulation::new(&s).unwrap();
    let body = |sim: &mut Simulation| sim.scene().instances[1].transform;
    let rest = body(&mut sim);
    sim.step();
    assert_eq!(body(&mut sim), rest);
    sim.step();
    let turned = body(&mut sim);
    let expected = glam::Mat4::from_rotation_y(90f32.to_radians()) * rest;
    assert!(turned.abs_diff_eq(expected, 1e-5));
    for _ in 0..5 {
        sim.step();
    }
    assert!(body(&mut sim).abs_diff_eq(expected, 1e-5), "rotated once only");

    // 45°/s at 0.1 s per frame: 36° after 8 frames.
    let s = with(
        "rotating_cone",
        "animations: [Rotate(entity: \"cone\", axis: (0, 1, 0), degrees_per_second: 45)]",
    );
    let mut sim = Simulation::new(&s).unwrap();
    let rest = body(&mut sim);
    for _ in 0..8 {
        sim.step();
    }
    let expected = glam::Mat4::from_rotation_y(36f32.to_radians()) * rest;
    assert!(body(&mut sim).abs_diff_eq(expected, 1e-4));
}

#[test]
fn flash_waveforms_drive_light_intensity_at_given_frames() {
    // Sine at 1.25 Hz with 0.1 s frames: frame 2 is t = 0.2 s -> sin(π/2) + 1 = 2.
    let s = with(
        "rotating_cone",
        "animations: [Flash(entity: \"lamp\", waveform: Sine(frequency: 1.25))]",
    );
    let mut sim = Simulation::new(&s).unwrap();
    let i0 = Vec3::splat(8.0);
    assert!((point_intensity(sim.scene()) - i0).length() < 1e-4, "frame 0: sin 0 + 1 = 1");
    sim.step();
    sim.step();
    assert!((point_intensity(sim.scene()) - 2.0 * i0).length() < 1e-4);
    for _ in 0..4 {
        sim.step();
    }
    // t = 0.6 s: sin(1.5π) + 1 = 0.
    assert!(point_intensity(sim.scene()).length() < 1e-4);

    // Square, period 0.4 s = 4 frames: on, on, off, off, on ...
    let s = with(
        "rotating_cone",
        "animations: [Flash(entity: \"lamp\", waveform: Square(period: 0.4))]",
    );
    let mut sim = Simulation::new(&s).unwrap();
    let mut on = vec![point_intensity(sim.scene()).x > 0.0];
    for _ in 0..7 {
        sim.step();
        on.push(point_intensity(sim.scene()).x > 0.0);
    }
    assert_eq!(on, [true, true, false, false, true, true, false, false]);

    // An emissive mesh flashes through its own copy of its material.
    let s = with(
        "cornell_box",
        "animations: [Flash(entity: \"ceiling_light\", waveform: Sine(frequency: 1.25))]",
    );
    let mut sim = Simulation::new(&s).unwrap();
    sim.step();
    sim.step();
    let scene = sim.scene();
    let light = scene.instances[5];
    assert!(
        (scene.materials[light.material as usize].emission - 2.0 * Vec3::new(17.0, 12.0, 4.0))
            .length()
            < 1e-3
    );
    assert_eq!(
        scene.materials[3].emission,
        Vec3::new(17.0, 12.0, 4.0),
        "the table entry is untouched"
    );
}

#[test]
fn events_toggle_move_and_repaint() {
    let mut sim =
        Simulation::new(&Scenario::load(&scenarios_dir().join("events.ron")).unwrap()).unwrap();
    let lamp_on = |s: &SceneDesc| point_intensity(s).length() > 0.0;
    let walls_before = sim.scene().materials[1];
    while sim.frame() < 19 {
        sim.step();
    }
    assert!(lamp_on(sim.scene()));
    sim.step();
    assert!(!lamp_on(sim.scene()), "lamp off at frame 20");
    let pillar = |s: &SceneDesc| {
        s.instances.iter().filter(|i| i.mesh == 1).map(|i| i.transform.w_axis.z).sum::<f32>()
    };
    let before = pillar(sim.scene());
    while sim.frame() < 30 {
        sim.step();
    }
    assert!((pillar(sim.scene()) - before - 1.5).abs() < 1e-4, "pillar_3 moved by 1.5 m");
    while sim.frame() < 40 {
        sim.step();
    }
    assert_eq!(sim.scene().materials[1].base_color, Vec3::new(0.3, 0.5, 0.8));
    assert_ne!(walls_before, sim.scene().materials[1]);
}

#[test]
fn keyframes_and_camera_path_follow_their_keys() {
    let mut sim =
        Simulation::new(&Scenario::load(&scenarios_dir().join("keyframes.ron")).unwrap()).unwrap();
    for _ in 0..10 {
        sim.step();
    }
    // Halfway between key 0 (0.35, 0.3, 0.3) and key 1 (0.1, 0.3, 0.5).
    let t = sim.scene().instances[7].transform.w_axis.truncate();
    assert!((t - Vec3::new(0.225, 0.3, 0.4)).length() < 1e-5, "{t}");

    let mut sim =
        Simulation::new(&Scenario::load(&scenarios_dir().join("camera_path.ron")).unwrap())
            .unwrap();
    assert!((sim.scene().camera.position - Vec3::new(0.0, 1.5, 0.6)).length() < 1e-5);
    for _ in 0..25 {
        sim.step();
    }
    let c = sim.scene().camera;
    assert!((c.position - Vec3::new(0.0, 1.5, -2.5)).length() < 1e-5);
    assert!((c.vfov - 70f32.to_radians()).abs() < 1e-5);
    let forward = (c.target - c.position).normalize();
    assert!((forward - (Vec3::new(0.0, 1.2, -4.0) - c.position).normalize()).length() < 1e-5);
}

#[test]
fn boids_scenario_keeps_the_flock_in_its_box() {
    let mut sim =
        Simulation::new(&Scenario::load(&scenarios_dir().join("boids.ron")).unwrap()).unwrap();
    let bird_mesh = 2;
    for _ in 0..60 {
        sim.step();
        assert!(sim.changed());
        let birds: Vec<Vec3> = sim
            .scene()
            .instances
            .iter()
            .filter(|i| i.mesh == bird_mesh)
            .map(|i| i.transform.w_axis.truncate())
            .collect();
        assert_eq!(birds.len(), 24, "the prototype is hidden, 24 boids fly");
        for (i, a) in birds.iter().enumerate() {
            assert!(
                a.cmpge(Vec3::new(-4.0, 1.5, -4.0) - 1e-4).all()
                    && a.cmple(Vec3::new(4.0, 4.0, 3.0) + 1e-4).all(),
                "{a}"
            );
            for b in &birds[i + 1..] {
                assert!(a.distance(*b) >= 0.5 * 0.999, "{} apart", a.distance(*b));
            }
        }
    }
}

/// The dynamic scene of every frame of `steps` steps.
fn run(scenario: &Scenario, steps: u32) -> Vec<SceneDesc> {
    let mut sim = Simulation::new(scenario).unwrap();
    let mut frames = Vec::new();
    for _ in 0..steps {
        sim.step();
        frames.push(SceneDesc { meshes: Vec::new(), textures: Vec::new(), ..sim.scene().clone() });
    }
    frames
}

#[test]
fn same_seed_same_scene_different_seed_differs() {
    for file in ["boids.ron", "strobe.ron", "events.ron", "keyframes.ron"] {
        let s = Scenario::load(&scenarios_dir().join(file)).unwrap();
        assert_eq!(run(&s, 20), run(&s, 20), "{file}: not deterministic");
    }
    for file in ["boids.ron", "strobe.ron"] {
        let a = Scenario::load(&scenarios_dir().join(file)).unwrap();
        let b = Scenario { seed: a.seed + 1, ..a.clone() };
        assert_ne!(run(&a, 20), run(&b, 20), "{file}: seed has no effect");
    }
}

#[test]
fn method_entries_keep_their_text_and_place() {
    let s = parse(
        "Scenario(scene: Builtin(\"courtyard\"), resolution: (32, 18), frames: 1,\n methods: [\n  Taa(),\n    HashCache(lookup: FirstHit,\n  taa: true), Taa(alpha: 0.2)])",
    );
    let entries: Vec<(&str, usize, usize)> =
        s.methods.iter().map(|m| (m.text.as_str(), m.line, m.column)).collect();
    assert_eq!(
        entries,
        [
            ("Taa()", 3, 3),
            ("HashCache(lookup: FirstHit,\n  taa: true)", 4, 5),
            ("Taa(alpha: 0.2)", 5, 15)
        ]
    );
    // A place inside the second entry, as a parser of that text reports it.
    assert_eq!(s.methods[1].position_in_file(1, 11), (4, 15));
    assert_eq!(s.methods[1].position_in_file(2, 3), (5, 3));
}

#[test]
fn extraction_reports_what_each_event_changed() {
    let s = with(
        "cornell_box",
        "events: [(frame: 2, action: MoveBy(entity: \"short_box\", offset: (0.1, 0, 0))),
                  (frame: 3, action: SetMaterial(material: \"red\", base_color: (1, 0, 0))),
                  (frame: 4, action: Toggle(entity: \"ceiling_light\"))]",
    );
    let mut sim = Simulation::new(&s).unwrap();
    assert_eq!(sim.changes(), SceneChanges::ALL);
    let mut seen = Vec::new();
    for _ in 0..5 {
        sim.step();
        seen.push(sim.changes());
    }
    assert!(!seen[0].any());
    assert_eq!(seen[1], SceneChanges { instances: true, ..Default::default() });
    assert!(seen[1].moved());
    assert_eq!(seen[2], SceneChanges { materials: true, ..Default::default() });
    // Toggling an emissive mesh changes its own material's emission.
    assert_eq!(seen[3], SceneChanges { materials: true, ..Default::default() });
    assert!(!seen[4].any());
}

#[test]
fn jod_display_and_exposure_have_defaults_and_a_bad_display_names_its_line() {
    let base = "Scenario(scene: Builtin(\"cornell_box\"), resolution: (32, 18), frames: 4, methods: [PathTracing(spp: 1)]";
    let s = Scenario::from_ron(&format!("{base})"), Path::new("d.ron")).unwrap();
    assert_eq!((s.cvvdp.display.as_str(), s.cvvdp.exposure), ("standard_fhd", 1.0));
    let s = Scenario::from_ron(
        &format!("{base}, cvvdp: (display: \"standard_4k\", exposure: 2.0))"),
        Path::new("d.ron"),
    )
    .unwrap();
    assert_eq!((s.cvvdp.display.as_str(), s.cvvdp.exposure), ("standard_4k", 2.0));
    let text = format!("{base},\n  cvvdp: (display: \"crt_1985\"),\n)");
    let e = Scenario::from_ron(&text, Path::new("d.ron")).unwrap_err().to_string();
    assert!(e.starts_with("d.ron:2:"), "{e}");
    assert!(e.contains("unknown display 'crt_1985'") && e.contains("standard_fhd"), "{e}");
    let text = format!("{base},\n  cvvdp: (exposure: 0.0),\n)");
    let e = Scenario::from_ron(&text, Path::new("d.ron")).unwrap_err().to_string();
    assert!(e.starts_with("d.ron:2:") && e.contains("exposure"), "{e}");
}
