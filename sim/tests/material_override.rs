//! A scenario's material overrides (subsurface parameters for sss): applied to the named
//! material of the spawned scene; bad values and unknown names are errors at file:line.

use std::path::Path;

use glam::Vec3;
use sim::{Scenario, Simulation};

fn text(materials: &str) -> String {
    format!(
        "Scenario(\n scene: Builtin(\"sss_sphere\"),\n resolution: (32, 18),\n frames: 2,\n methods: [PathTracing(spp: 1)],\n materials: [{materials}],\n)"
    )
}

fn load(materials: &str) -> Result<Scenario, String> {
    Scenario::from_ron(&text(materials), Path::new("inline.ron")).map_err(|e| e.to_string())
}

#[test]
fn subsurface_override_reaches_the_named_material() {
    let scenario = load("(material: \"skin\", subsurface: (dmfp: (0.3, 0.12, 0.06)))").unwrap();
    let sim = Simulation::new(&scenario).unwrap();
    let with: Vec<_> = sim.scene().materials.iter().filter_map(|m| m.subsurface).collect();
    assert_eq!(with.len(), 1);
    assert_eq!(with[0].dmfp, Vec3::new(0.3, 0.12, 0.06));
    // Without the override the scene has no subsurface material.
    let plain = Simulation::new(&load("").unwrap()).unwrap();
    assert!(plain.scene().materials.iter().all(|m| m.subsurface.is_none()));
}

#[test]
fn bad_overrides_are_errors_at_file_line() {
    let e = load("(material: \"skin\", subsurface: (dmfp: (0.3, -1.0, 0.06)))").unwrap_err();
    assert!(e.starts_with("inline.ron:6:") && e.contains("dmfp") && e.contains("positive"), "{e}");
    // Zero and non-finite dmfp: refused at the same line (nothing is played).
    for bad in ["0.0", "inf", "NaN"] {
        let e = load(&format!("(material: \"skin\", subsurface: (dmfp: (0.3, {bad}, 0.06)))"))
            .unwrap_err();
        assert!(e.starts_with("inline.ron:6:") && e.contains("dmfp"), "{bad}: {e}");
    }
    let e = load("(material: \"skin\", subsurface: (mfp: (0.3, 0.1, 0.06)))").unwrap_err();
    assert!(e.starts_with("inline.ron:6:") && e.contains("mfp"), "{e}");
    let scenario = load("(material: \"skn\", subsurface: (dmfp: (0.3, 0.1, 0.06)))").unwrap();
    let e = Simulation::new(&scenario).err().expect("unknown material").to_string();
    assert!(e.contains("inline.ron:6:") && e.contains("skn") && e.contains("skin"), "{e}");
}

#[test]
fn the_random_walk_reference_is_refused_with_media_and_kept_out_of_other_manifests() {
    let with = |extra: &str| {
        format!(
            "Scenario(\n scene: Builtin(\"sss_sphere\"),\n resolution: (32, 18),\n frames: 2,\n methods: [PathTracing(spp: 1)],\n reference: (spp: 4, frames: Every(1), random_walk: true),\n{extra})"
        )
    };
    let ok = Scenario::from_ron(
        &with(" materials: [(material: \"skin\", subsurface: (dmfp: (0.3, 0.12, 0.06)))],\n"),
        Path::new("inline.ron"),
    )
    .unwrap();
    assert!(ok.reference.random_walk);
    assert!(Simulation::new(&ok).is_ok());
    let media = " media: [(name: \"fog\", kind: Homogeneous, box_min: (-1.0, 0.0, -1.0), box_max: (1.0, 1.0, 1.0), sigma_t: 1.0)],\n";
    let e = Scenario::from_ron(&with(media), Path::new("inline.ron")).unwrap_err().to_string();
    assert!(e.starts_with("inline.ron:6:") && e.contains("random_walk"), "{e}");
    // Off (the default), the setting is not serialised: other scenarios' manifests unchanged.
    let plain = load("").unwrap();
    assert!(!plain.reference.random_walk);
    assert!(!ron::to_string(&plain.reference).unwrap().contains("random_walk"));
}
