//! Participating media in scenario files: parsed with their defaults, absent by default, and
//! bad declarations refused with the file and the line of the medium.

use std::path::Path;

use scene::DensityKind;
use sim::Scenario;

fn parse(text: &str) -> Result<Scenario, sim::ScenarioError> {
    Scenario::from_ron(text, Path::new("volume.ron"))
}

fn scenario(medium: &str) -> String {
    format!("Scenario(scene: Builtin(\"cornell_box\"), resolution: (32, 18), frames: 1,\n methods: [PathTracing(spp: 1)],\n media: [\n  {medium},\n ])")
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
        (r#"(name: "flat", kind: Homogeneous, box_min: (0, 0, 0), box_max: (1, 0, 1), sigma_t: 1.0)"#, "box_min"),
        (r#"(name: "neg", kind: Homogeneous, box_min: (0, 0, 0), box_max: (1, 1, 1), sigma_t: -1.0)"#, "sigma_t"),
        (r#"(name: "big", kind: Homogeneous, box_min: (0, 0, 0), box_max: (1, 1, 1), sigma_t: 1.0, resolution: (0, 8, 8))"#, "resolution"),
        (r#"(name: "bright", kind: Homogeneous, box_min: (0, 0, 0), box_max: (1, 1, 1), sigma_t: 1.0, albedo: (2, 0, 0))"#, "albedo"),
        (r#"(name: "x", kind: Smoke, box_min: (0, 0, 0), box_max: (1, 1, 1), sigma_t: 1.0)"#, "Smoke"),
    ];
    for (medium, word) in cases {
        let e = parse(&scenario(medium)).unwrap_err();
        let text = e.to_string();
        assert!(text.starts_with("volume.ron:4:"), "{text}");
        assert!(text.contains(word), "{text}");
    }
}
