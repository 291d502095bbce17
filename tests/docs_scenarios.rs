//! The documents' scenarios load as `flicker run` loads a scenario (its methods' settings
//! included), and a document's copy of a shipped scenario is that file, word for word. A
//! ```ron block is:
//! - a shipped file when its first line is `// scenarios/PATH.ron`: the block must equal the
//!   file's text, and the file must load;
//! - a whole scenario when it starts (after its comments) with `Scenario(`: it must load;
//! - a part of one when it starts with a scenario field (`methods:`, `animations:`, `events:`,
//!   `media:`, `materials:`, `regions:`, `reference:`, `camera:`, `cvvdp:`): it must load inside
//!   a minimal scenario of the Cornell box, 1000 frames long (entity names are the scene's
//!   business, not checked);
//! - anything else (suites, sweeps, claims, single entries): not read here.

mod docs_common;

use std::path::Path;

use docs_common::{Doc, documents, root};
use playback::scenario::{Overrides, RunSpec};
use pulldown_cmark::{CodeBlockKind, Event, Tag, TagEnd};

/// The scenario fields a part of a scenario may start with.
const FIELDS: [&str; 9] = [
    "methods:",
    "animations:",
    "events:",
    "media:",
    "materials:",
    "regions:",
    "reference:",
    "camera:",
    "cvvdp:",
];

/// Each ```ron block of `doc`: its place and text.
fn ron_blocks(doc: &Doc) -> Vec<(String, String)> {
    let mut out = Vec::new();
    let mut current: Option<(String, String)> = None;
    for (event, range) in doc.events() {
        match event {
            Event::Start(Tag::CodeBlock(CodeBlockKind::Fenced(info)))
                if info.split_whitespace().next() == Some("ron") =>
            {
                // The block's text starts on the line after the fence.
                current = Some((doc.place(range.start + 1), String::new()));
            }
            Event::Text(t) => {
                if let Some((_, text)) = &mut current {
                    text.push_str(&t);
                }
            }
            Event::End(TagEnd::CodeBlock) => out.extend(current.take()),
            _ => {}
        }
    }
    out
}

/// The block's text without its leading comment lines and blank lines.
fn body(text: &str) -> &str {
    let mut rest = text;
    while let Some(line) = rest.lines().next() {
        let t = line.trim();
        if !(t.is_empty() || t.starts_with("//")) {
            break;
        }
        rest = rest[line.len()..].strip_prefix('\n').unwrap_or(&rest[line.len()..]);
    }
    rest.trim_start()
}

/// Loads `text` as a scenario whose file would be `origin` (so relative paths resolve there).
fn load(text: &str, origin: &Path) -> Result<(), String> {
    let scenario = sim::Scenario::from_ron(text, origin).map_err(|e| format!("{e}"))?;
    RunSpec::from_scenario(scenario, &Overrides::default()).map_err(|e| format!("{e:#}"))?;
    Ok(())
}

/// What is wrong with one block; `Ok(true)` when it was checked, `Ok(false)` when it is not a
/// scenario's.
fn check(doc: &Doc, text: &str) -> Result<bool, String> {
    let first = text.lines().next().unwrap_or("").trim();
    if let Some(path) = first.strip_prefix("// ").filter(|p| p.starts_with("scenarios/")) {
        let file = root().join(path);
        let shipped = std::fs::read_to_string(&file)
            .map_err(|e| format!("names the shipped file {path}, which cannot be read: {e}"))?;
        if shipped != text {
            return Err(format!(
                "differs from {path}; expected the block to be the file's text, word for word"
            ));
        }
        RunSpec::load(&file, &Overrides::default()).map_err(|e| format!("{e:#}"))?;
        return Ok(true);
    }
    let origin = root().join(&doc.path);
    let b = body(text);
    if b.starts_with("Scenario(") {
        return load(text, &origin).map(|()| true);
    }
    if FIELDS.iter().any(|f| b.starts_with(f)) {
        let has_methods = b.lines().any(|l| l.trim_start().starts_with("methods:"));
        let methods = if has_methods { "" } else { "methods: [PathTracing(spp: 1)]," };
        let whole = format!(
            "Scenario(scene: Builtin(\"cornell_box\"), resolution: (8, 8), frames: 1000, {methods}\n{}\n)",
            b.trim_end().trim_end_matches(',')
        );
        return load(&whole, &origin).map(|()| true);
    }
    Ok(false)
}

#[test]
fn the_documents_scenarios_load_and_their_copies_of_shipped_files_are_the_files() {
    let (mut checked, mut errors) = (0, Vec::new());
    for doc in documents() {
        for (place, text) in ron_blocks(&doc) {
            match check(&doc, &text) {
                Ok(c) => checked += usize::from(c),
                Err(e) => errors.push(format!("{place}: {e}")),
            }
        }
    }
    assert!(errors.is_empty(), "{} scenario blocks wrong:\n{}", errors.len(), errors.join("\n"));
    // The guide's first scenario, the reference's file, the tutorial's four steps, the parts of
    // scenarios.md and each method's page: 19 blocks when this test was written.
    eprintln!("{checked} scenario blocks checked");
    assert!(checked >= 19, "only {checked} scenario blocks found; the block parser broke?");
}

#[test]
fn a_changed_copy_a_bad_field_and_an_unknown_method_setting_fail() {
    let doc = Doc::new("docs/example.md", "");
    let shipped = std::fs::read_to_string(root().join("scenarios/tutorial/1_scene.ron")).unwrap();
    assert_eq!(check(&doc, &shipped), Ok(true));
    let changed = shipped.replace("frames: 20", "frames: 21");
    assert!(check(&doc, &changed).unwrap_err().contains("differs from"), "a changed copy");
    let bad =
        "Scenario(scene: Builtin(\"cornell_box\"), resolution: (8, 8), frame: 1, methods: [])";
    assert!(check(&doc, bad).is_err(), "an unknown field");
    let setting = "    methods: [Taa(alpha_typo: 0.1)],\n";
    assert!(check(&doc, setting).is_err(), "an unknown method setting");
    assert_eq!(check(&doc, "Suite(\n)"), Ok(false));
}
