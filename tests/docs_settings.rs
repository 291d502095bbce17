//! The settings tables of the documents against the Rust types: for every
//! `<!-- settings: crate::path::Type -->` marker in README.md, docs/** and the crate READMEs,
//! the table below it has one row per field of the type and no other, and its default column
//! is what the field is when a scenario leaves it out (see `serde_shape` for how that is read
//! from serde). Every type of [`registry`] (the scenario file's and every shipped method's
//! settings) must have a table somewhere.

mod docs_common;
#[path = "docs_settings/serde_shape.rs"]
mod serde_shape;
#[path = "docs_settings/tables.rs"]
mod tables;

use docs_common::{Doc, documents};
use playback::methods::MethodPlugin;
use playback::methods::registry::PluginVisitor;
use serde_shape::{Shape, struct_shape, variant_shape};

/// A settings type the documents may name in a marker: its path as the marker writes it and
/// how to read its shape.
struct Entry {
    name: String,
    shape: fn() -> Result<Shape, String>,
}

fn path_name(tokens: &str) -> String {
    tokens.split_whitespace().collect()
}

/// `settings!(crate::path::Type, "minimal RON")`: a struct; the minimal text gives exactly its
/// required fields.
macro_rules! settings {
    ($($p:ident)::+, $minimal:expr) => {
        Entry {
            name: path_name(stringify!($($p)::+)),
            shape: || struct_shape::<$($p)::+>($minimal),
        }
    };
}

/// `variant!(crate::path::Enum::Variant, "Variant(required...)")`: a struct variant.
macro_rules! variant {
    ($($p:ident)::+ => $v:ident, $minimal:expr) => {
        Entry {
            name: format!("{}::{}", path_name(stringify!($($p)::+)), stringify!($v)),
            shape: || variant_shape::<$($p)::+>(stringify!($v), $minimal),
        }
    };
}

/// A method's settings: named as the type is defined (`sample_cache::settings::SampleCacheSettings`),
/// which a marker may write as its crate's re-export (`sample_cache::SampleCacheSettings`), and
/// read from the plugin's `MINIMAL_SETTINGS`.
fn method_entry<P: MethodPlugin>() -> Entry {
    Entry {
        name: std::any::type_name::<P::Settings>().to_string(),
        shape: || struct_shape::<P::Settings>(P::MINIMAL_SETTINGS),
    }
}

/// The registered methods' settings, by method name, read from the registry.
fn methods() -> Vec<(&'static str, Entry)> {
    struct Settings(Vec<(&'static str, Entry)>);
    impl PluginVisitor for Settings {
        fn visit<P: MethodPlugin>(&mut self) {
            self.0.push((P::NAME, method_entry::<P>()));
        }
    }
    let mut settings = Settings(Vec::new());
    playback::methods::registry::visit_shipped(&mut settings);
    settings.0
}

/// Whether a marker's path names the entry's type: the same path, or the same crate and type
/// name (a re-export at the crate's root).
fn names_entry(marker: &str, entry: &str) -> bool {
    let ends = |p: &str| {
        let mut parts = p.split("::");
        (parts.next().map(str::to_string), p.rsplit("::").next().map(str::to_string))
    };
    marker == entry || (marker.split("::").count() == 2 && ends(marker) == ends(entry))
}

/// Every type that must have a table: the scenario file's, and every method's settings with
/// the settings structs they nest.
fn registry() -> Vec<Entry> {
    let mut out = vec![
        settings!(
            sim::scenario_file::ScenarioFile,
            r#"(scene: Builtin("cornell_box"), resolution: (1, 1), frames: 1, methods: [PathTracing(spp: 1)])"#
        ),
        settings!(sim::scenario::CameraSpec, "(position: (0, 0, 1), target: (0, 0, 0))"),
        settings!(sim::scenario::ReferenceSpec, "(spp: 1, frames: None)"),
        settings!(sim::scenario::Region, r#"(name: "r", x: 0, y: 0, width: 1, height: 1)"#),
        variant!(sim::scenario::AnimationSpec => Rotate, r#"Rotate(entity: "e", axis: (0, 1, 0), degrees_per_second: 1)"#),
        variant!(sim::scenario::AnimationSpec => RotateOnce, r#"RotateOnce(entity: "e", axis: (0, 1, 0), degrees: 1, frame: 1)"#),
        variant!(sim::scenario::AnimationSpec => Flash, r#"Flash(entity: "e", waveform: Sine(frequency: 1))"#),
        variant!(sim::scenario::AnimationSpec => Boids, r#"Boids(prototype: "e", count: 1)"#),
        variant!(sim::scenario::AnimationSpec => Keyframes, r#"Keyframes(entity: "e", keys: [])"#),
        variant!(sim::scenario::AnimationSpec => CameraPath, "CameraPath(keys: [])"),
        settings!(sim::scenario::KeySpec, "(frame: 0)"),
        settings!(sim::scenario::AxisAngle, "(axis: (0, 1, 0), degrees: 1)"),
        settings!(
            sim::scenario::CameraKeySpec,
            "(frame: 0, position: (0, 0, 1), target: (0, 0, 0))"
        ),
        settings!(sim::scenario::EventSpec, r#"(frame: 0, action: Toggle(entity: "e"))"#),
        variant!(sim::scenario::ActionSpec => RotateLight, r#"RotateLight(light: "l", axis: (0, 1, 0), degrees: 1)"#),
        variant!(sim::scenario::ActionSpec => Rotate, r#"Rotate(entity: "e", axis: (0, 1, 0), degrees: 1)"#),
        variant!(sim::scenario::ActionSpec => Toggle, r#"Toggle(entity: "e")"#),
        variant!(sim::scenario::ActionSpec => MoveTo, r#"MoveTo(entity: "e", translation: (0, 0, 0))"#),
        variant!(sim::scenario::ActionSpec => MoveBy, r#"MoveBy(entity: "e", offset: (0, 0, 0))"#),
        variant!(sim::scenario::ActionSpec => SetMaterial, r#"SetMaterial(material: "m")"#),
        settings!(sim::scenario::MaterialOverride, r#"(material: "m")"#),
        settings!(scene::Subsurface, "(dmfp: (1, 1, 1))"),
        settings!(metrics::CvvdpSettings, "()"),
        settings!(
            scene::MediumDesc,
            r#"(name: "m", kind: Homogeneous, box_min: (0, 0, 0), box_max: (1, 1, 1), sigma_t: 1)"#
        ),
        settings!(scene::MediumMotion, "()"),
        // What the methods' settings nest.
        settings!(nirc::NircCacheSettings, "()"),
        settings!(nirc::config::HashGridSettings, "()"),
        settings!(nirc::config::NetworkSettings, "()"),
        settings!(nirc::optimizer_config::AdamSettings, "()"),
        settings!(nirc::config::LossSettings, "()"),
        settings!(nirc::optimizer_config::EmaSettings, "()"),
        settings!(nirc::config::ReliabilitySettings, "()"),
        settings!(nirc::CachePathSettings, "()"),
        settings!(sss::SpvgSettings, "()"),
        settings!(sss::Prefilter, "()"),
        settings!(sss::Split, "()"),
        settings!(sss::Hybrid, "()"),
    ];
    out.extend(methods().into_iter().map(|(_, e)| e));
    out
}

/// The shape of the registered type whose path is `name`, or whose path ends in `::name`.
fn lookup(entries: &[Entry], name: &str) -> Option<Result<Shape, String>> {
    let suffix = format!("::{name}");
    entries.iter().find(|e| e.name == name || e.name.ends_with(&suffix)).map(|e| (e.shape)())
}

/// Every problem of `docs`' settings tables against `entries`, as `file:line: what`, and the
/// names of the types that have a table.
fn check_documents(docs: &[Doc], entries: &[Entry]) -> (Vec<String>, Vec<String>) {
    let (mut errors, mut documented) = (Vec::new(), Vec::new());
    let linked = |name: &str| lookup(entries, name).and_then(Result::ok);
    for doc in docs {
        let tables = match tables::tables(doc) {
            Ok(t) => t,
            Err(e) => {
                errors.extend(e);
                continue;
            }
        };
        for table in tables {
            let Some(entry) = entries.iter().find(|e| names_entry(&table.type_name, &e.name))
            else {
                errors.push(format!(
                    "{}: `{}` is no registered settings type (tests/docs_settings.rs's registry)",
                    table.place, table.type_name
                ));
                continue;
            };
            match (entry.shape)() {
                Ok(shape) => errors.extend(tables::check(&table, &shape, &linked)),
                Err(e) => errors.push(format!("{}: {}: {e}", table.place, table.type_name)),
            }
            documented.push(entry.name.clone());
        }
    }
    (errors, documented)
}

#[test]
fn settings_tables_match_the_types() {
    let docs = documents();
    let entries = registry();
    let (errors, documented) = check_documents(&docs, &entries);
    assert!(
        errors.is_empty(),
        "{} problems in settings tables:\n{}",
        errors.len(),
        errors.join("\n")
    );
    eprintln!("{} settings tables checked", documented.len());
}

#[test]
fn every_settings_type_has_a_table() {
    let (_, documented) = check_documents(&documents(), &registry());
    let missing: Vec<String> =
        registry().into_iter().map(|e| e.name).filter(|n| !documented.contains(n)).collect();
    assert!(
        missing.is_empty(),
        "{} settings types have no table in README.md, docs/ or a crate README (add \
         `<!-- settings: TYPE -->` and its table):\n{}",
        missing.len(),
        missing.join("\n")
    );
}

/// A method added to the registry without its settings here fails, so the list above stays
/// complete.
#[test]
fn every_shipped_method_has_its_settings_registered() {
    let listed: Vec<&str> = methods().iter().map(|(n, _)| *n).collect();
    for name in playback::methods::registry::names() {
        assert!(
            listed.contains(&name),
            "method {name}: add its settings to tests/docs_settings.rs's methods()"
        );
    }
}

/// A settings struct nested in a registered type (`NircSettings.cache: NircCacheSettings`) is
/// registered too, so that it needs a table.
#[test]
fn nested_settings_structs_are_registered() {
    let entries = registry();
    let mut missing = Vec::new();
    for e in &entries {
        for (field, name) in (e.shape)().map(|s| s.nested).unwrap_or_default() {
            if lookup(&entries, &name).is_none() {
                missing.push(format!("{}.{field}: {name}", e.name));
            }
        }
    }
    assert!(
        missing.is_empty(),
        "settings structs missing from the registry:\n{}",
        missing.join("\n")
    );
    let nirc = lookup(&entries, "NircSettings").unwrap().unwrap().nested;
    assert!(nirc.contains(&("cache".to_string(), "NircCacheSettings".to_string())), "{nirc:?}");
}

/// Every registered type's shape can be read (its minimal text parses, and gives exactly its
/// required fields).
#[test]
fn every_registered_shape_reads() {
    for e in registry() {
        if let Err(err) = (e.shape)() {
            panic!("{}: {err}", e.name);
        }
    }
}

// The checker on small fixtures: a table that is right passes, and each deliberate break fails
// naming the file and line.

const TAA_FIXTURE: &str = include_str!("docs_settings/fixture_taa.md");

fn fixture_errors(text: &str) -> Vec<String> {
    check_documents(&[Doc::new("fixture.md", text)], &registry()).0
}

#[test]
fn a_right_table_passes() {
    assert_eq!(fixture_errors(TAA_FIXTURE), Vec::<String>::new());
    let camera = "<!-- settings: sim::scenario::CameraSpec -->\n\
        | field | default | meaning |\n|---|---|---|\n\
        | `position` | required | eye |\n| `target` | required | look-at point |\n\
        | `up` | `(0.0, 1.0, 0.0)` | up |\n| `vfov_degrees` | `45.0` | vertical field of view |\n";
    assert_eq!(fixture_errors(camera), Vec::<String>::new());
    // A field the serializer leaves out at its default (`skip_serializing_if`).
    let reference = "<!-- settings: sim::scenario::ReferenceSpec -->\n\
        | field | default | meaning |\n|---|---|---|\n\
        | `spp` | required | x |\n| `frames` | required | x |\n| `random_walk` | `false` | x |\n";
    assert_eq!(fixture_errors(reference), Vec::<String>::new());
}

/// `TAA_FIXTURE` with `from` replaced by `to` (which must occur once).
fn broken(from: &str, to: &str) -> String {
    assert_eq!(TAA_FIXTURE.matches(from).count(), 1, "{from}");
    TAA_FIXTURE.replace(from, to)
}

fn assert_fails(text: &str, line: usize, expected: &str) {
    let errors = fixture_errors(text);
    assert_eq!(errors.len(), 1, "{errors:#?}");
    assert!(errors[0].starts_with(&format!("fixture.md:{line}: ")), "{}", errors[0]);
    assert!(errors[0].contains(expected), "{}", errors[0]);
}

#[test]
fn a_wrong_default_fails() {
    assert_fails(
        &broken("| `alpha` | `0.1` |", "| `alpha` | `0.2` |"),
        6,
        "TaaSettings.alpha defaults to `0.1`, not `0.2`",
    );
    assert_fails(
        &broken("`Variance(gamma: 1.0)`", "`Variance(gamma: 2.0)`"),
        7,
        "defaults to `Variance(gamma:1.0)`, not `Variance(gamma: 2.0)`",
    );
    assert_fails(
        &broken("| `alpha` | `0.1` |", "| `alpha` | required |"),
        6,
        "documented `required` but has a default",
    );
    assert_fails(
        &broken("| `alpha` | `0.1` |", "| `alpha` | 0.1 |"),
        6,
        "expected the RON text in backticks",
    );
    let skipped = "<!-- settings: sim::scenario::ReferenceSpec -->\n\
        | field | default | meaning |\n|---|---|---|\n\
        | `spp` | required | x |\n| `frames` | required | x |\n| `random_walk` | `true` | x |\n";
    assert_fails(skipped, 6, "ReferenceSpec.random_walk is not `true` by default");
    let not_required = skipped.replace("| `spp` | required |", "| `spp` | `64` |");
    let errors = fixture_errors(&not_required);
    assert!(
        errors.iter().any(|e| e.starts_with("fixture.md:4: ")
            && e.contains("has no default; expected `required`")),
        "{errors:#?}"
    );
}

#[test]
fn a_missing_field_row_fails() {
    assert_fails(
        &broken("| `max_history` | `256.0` | history cap |\n", ""),
        3,
        "TaaSettings's field `max_history` has no row",
    );
}

#[test]
fn a_bogus_field_row_fails() {
    assert_fails(
        &broken(
            "| `alpha` | `0.1` | weight of the current frame |\n",
            "| `alpha` | `0.1` | weight of the current frame |\n| `beta` | `0.5` | no such field |\n",
        ),
        7,
        "`beta` is not a field of taa::TaaSettings",
    );
    // A field cell that is no code span: the row is refused, and the field then lacks a row.
    let errors = fixture_errors(&broken("| `alpha` |", "| alpha |"));
    assert!(
        errors
            .iter()
            .any(|e| e.starts_with("fixture.md:6: ") && e.contains("expected one code span")),
        "{errors:#?}"
    );
    assert!(errors.iter().any(|e| e.contains("field `alpha` has no row")), "{errors:#?}");
}

#[test]
fn an_unknown_type_or_a_stray_marker_fails() {
    assert_fails(
        &broken("taa::TaaSettings", "taa::TaaSetings"),
        3,
        "`taa::TaaSetings` is no registered settings type",
    );
    assert_fails(
        "text\n\n<!-- settings: taa::TaaSettings -->\n\nno table here\n",
        3,
        "not followed by its table",
    );
    assert_fails(
        &broken("| field | default | meaning |", "| name | default | meaning |"),
        3,
        "expected | field | default | meaning |",
    );
}

#[test]
fn links_to_nested_types_are_checked() {
    let nirc = "<!-- settings: nirc::plugin::NircSettings -->\n\
        | field | default | meaning |\n|---|---|---|\n\
        | `spp` | required | x |\n| `predictor` | `Blend` | x |\n\
        | `cache` | [`NircCacheSettings`](#nircconfig) | x |\n| `paths` | [`CachePathSettings`](#x) | x |\n\
        | `pretrain_frames` | `0` | x |\n| `test_skip_ema` | `false` | x |\n";
    assert_eq!(fixture_errors(nirc), Vec::<String>::new());
    assert_fails(
        &nirc.replace("[`NircCacheSettings`]", "[`NircConfg`]"),
        6,
        "links to `NircConfg`, which is no registered settings type",
    );
    assert_fails(
        &nirc.replace("[`NircCacheSettings`]", "[`HashGridSettings`]"),
        6,
        "not to HashGridSettings's defaults",
    );
}
