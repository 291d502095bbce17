//! Every relative link and image in the documents (README.md, CONTRIBUTING.md, docs/**, crate
//! READMEs) points at a file or folder of the repository, and every `#anchor` at a heading of the
//! linked Markdown file by GitHub's slug rules (or at a line, `#L12`, of another file).
//! External links (a scheme such as https:) are not fetched.

mod docs_common;

use std::collections::HashMap;
use std::path::{Component, Path, PathBuf};

use docs_common::{Doc, documents, root};
use pulldown_cmark::{Event, Tag, TagEnd};

/// GitHub's anchor of a heading: lowercase, every character that is not a letter, a digit, a
/// space, `-` or `_` dropped, spaces to `-`. A repeated slug gets `-1`, `-2`, ... appended.
fn slug(heading: &str) -> String {
    heading
        .trim()
        .to_lowercase()
        .chars()
        .filter(|c| c.is_alphanumeric() || matches!(c, ' ' | '-' | '_'))
        .map(|c| if c == ' ' { '-' } else { c })
        .collect()
}

/// Every anchor of a document: its headings' slugs (with GitHub's numbering of repeats) and
/// explicit `<a id="...">` / `<a name="...">` targets.
fn anchors(doc: &Doc) -> Vec<String> {
    let mut out = Vec::new();
    let mut seen: HashMap<String, usize> = HashMap::new();
    let mut heading: Option<String> = None;
    for (event, _) in doc.events() {
        match event {
            Event::Start(Tag::Heading { .. }) => heading = Some(String::new()),
            Event::End(TagEnd::Heading(_)) => {
                let base = slug(&heading.take().unwrap_or_default());
                let n = seen.entry(base.clone()).or_insert(0);
                out.push(if *n == 0 { base.clone() } else { format!("{base}-{n}") });
                *n += 1;
            }
            Event::Text(t) | Event::Code(t) => {
                if let Some(h) = heading.as_mut() {
                    h.push_str(&t);
                }
            }
            Event::Html(h) | Event::InlineHtml(h) => {
                for key in ["id=\"", "name=\""] {
                    let mut rest = &*h;
                    while let Some(i) = rest.find(key) {
                        rest = &rest[i + key.len()..];
                        if let Some(end) = rest.find('"') {
                            out.push(rest[..end].to_string());
                        }
                    }
                }
            }
            _ => {}
        }
    }
    out
}

/// Whether `dest` names another site or protocol (http:, https:, mailto:, ...).
fn is_external(dest: &str) -> bool {
    let scheme = dest.split(':').next().unwrap_or("");
    dest.contains(':')
        && !scheme.is_empty()
        && scheme.chars().all(|c| c.is_ascii_alphanumeric() || "+-.".contains(c))
}

/// `%20` and the like in a link's path.
fn percent_decode(s: &str) -> String {
    let bytes = s.as_bytes();
    let mut out = Vec::with_capacity(bytes.len());
    let mut i = 0;
    while i < bytes.len() {
        if bytes[i] == b'%'
            && i + 2 < bytes.len()
            && let Ok(b) = u8::from_str_radix(&s[i + 1..i + 3], 16)
        {
            out.push(b);
            i += 3;
        } else {
            out.push(bytes[i]);
            i += 1;
        }
    }
    String::from_utf8_lossy(&out).into_owned()
}

/// `base/rel` with `.` and `..` folded; None where it climbs above the repository.
fn join_inside(base: &Path, rel: &str) -> Option<PathBuf> {
    let mut parts: Vec<PathBuf> = Vec::new();
    let start = if rel.starts_with('/') { PathBuf::new() } else { base.to_path_buf() };
    for c in start.join(rel.trim_start_matches('/')).components() {
        match c {
            Component::CurDir => {}
            Component::ParentDir => {
                parts.pop()?;
            }
            Component::Normal(p) => parts.push(PathBuf::from(p)),
            _ => return None,
        }
    }
    Some(parts.iter().collect())
}

/// The broken links of `doc`, as `file:line: what`. `read` gives another document's text by
/// its path relative to `root` (None: no such file), `exists` whether a path is a file or
/// folder of the repository.
fn broken_links(
    doc: &Doc,
    exists: &dyn Fn(&Path) -> bool,
    read: &dyn Fn(&Path) -> Option<String>,
) -> Vec<String> {
    let mut errors = Vec::new();
    let folder = doc.path.parent().unwrap_or(Path::new("")).to_path_buf();
    for (event, range) in doc.events() {
        let (dest, what) = match event {
            Event::Start(Tag::Link { dest_url, .. }) => (dest_url, "link"),
            Event::Start(Tag::Image { dest_url, .. }) => (dest_url, "image"),
            _ => continue,
        };
        if dest.is_empty() || is_external(&dest) {
            continue;
        }
        let place = doc.place(range.start);
        let (path_part, anchor) = match dest.split_once('#') {
            Some((p, a)) => (p, Some(a)),
            None => (&*dest, None),
        };
        let path_part = path_part.split('?').next().unwrap_or("");
        let target = if path_part.is_empty() {
            doc.path.clone()
        } else {
            match join_inside(&folder, &percent_decode(path_part)) {
                Some(t) => t,
                None => {
                    errors.push(format!(
                        "{place}: {what} `{dest}` leaves the repository; expected a path inside it"
                    ));
                    continue;
                }
            }
        };
        if !exists(&target) {
            errors.push(format!("{place}: {what} `{dest}`: {} does not exist", target.display()));
            continue;
        }
        let Some(anchor) = anchor else { continue };
        if target.extension().is_some_and(|e| e == "md") {
            let text = if target == doc.path { Some(doc.text.clone()) } else { read(&target) };
            let Some(text) = text else { continue };
            let known = anchors(&Doc::new(target.clone(), text));
            if !known.iter().any(|a| a == &percent_decode(anchor)) {
                errors.push(format!(
                    "{place}: {what} `{dest}`: {} has no heading with anchor `#{anchor}` (its anchors: {})",
                    target.display(),
                    known.join(", ")
                ));
            }
        } else if !is_line_anchor(anchor) {
            errors.push(format!(
                "{place}: {what} `{dest}`: `#{anchor}` on a file that is not Markdown; expected a line anchor such as #L12 or #L12-L20"
            ));
        }
    }
    errors
}

/// GitHub's line anchors: `L12` or `L12-L20`.
fn is_line_anchor(a: &str) -> bool {
    let line = |s: &str| {
        s.strip_prefix('L').is_some_and(|n| !n.is_empty() && n.bytes().all(|b| b.is_ascii_digit()))
    };
    match a.split_once('-') {
        Some((x, y)) => line(x) && line(y),
        None => line(a),
    }
}

#[test]
fn every_relative_link_and_anchor_exists() {
    let root = root();
    let exists = |p: &Path| root.join(p).exists();
    let read = |p: &Path| std::fs::read_to_string(root.join(p)).ok();
    let docs = documents();
    let errors: Vec<String> = docs.iter().flat_map(|d| broken_links(d, &exists, &read)).collect();
    assert!(errors.is_empty(), "{} broken links:\n{}", errors.len(), errors.join("\n"));
    eprintln!("links checked in {} documents", docs.len());
}

/// A small repository in memory: the files that exist and the texts of its Markdown files.
fn fixture_check(doc_path: &str, text: &str, files: &[(&str, &str)]) -> Vec<String> {
    let doc = Doc::new(doc_path, text);
    let exists = |p: &Path| {
        p == doc.path || files.iter().any(|(f, _)| Path::new(f) == p || Path::new(f).starts_with(p))
    };
    let read = |p: &Path| files.iter().find(|(f, _)| Path::new(f) == p).map(|(_, t)| t.to_string());
    broken_links(&doc, &exists, &read)
}

#[test]
fn slugs_follow_github() {
    assert_eq!(slug("Use it"), "use-it");
    assert_eq!(slug("`flicker run`: what it writes"), "flicker-run-what-it-writes");
    assert_eq!(slug("Departures from the paper (§3.2)"), "departures-from-the-paper-32");
    assert_eq!(slug("snake_case and-dash"), "snake_case-and-dash");
    let doc = Doc::new("a.md", "# Settings\n\n## Settings\n\n## `Taa` settings\n");
    assert_eq!(anchors(&doc), ["settings", "settings-1", "taa-settings"]);
}

#[test]
fn good_links_pass() {
    let files = [
        ("docs/methods/nirc.md", "# NIRC\n\n## Settings\n\ntext\n"),
        ("scenarios/cornell_box.ron", ""),
        ("methods/nirc/src/plugin.rs", ""),
    ];
    let text = "See [settings](methods/nirc.md#settings), [the box](../scenarios/cornell_box.ron), \
                [code](../methods/nirc/src/plugin.rs#L40-L60), [here](#top), [web](https://example.org/x#y), \
                [folder](../scenarios/).\n\n# Top\n";
    assert_eq!(fixture_check("docs/guide.md", text, &files), Vec::<String>::new());
}

/// The deliberate breaks: a missing file, a missing anchor, an image that is not there, a
/// link out of the repository, a fragment on a source file that is not a line.
#[test]
fn broken_links_fail_naming_file_and_line() {
    let files = [("docs/methods/nirc.md", "# NIRC\n\n## Settings\n")];
    let cases = [
        ("[x](methods/nirc_typo.md)", "docs/methods/nirc_typo.md does not exist"),
        ("[x](methods/nirc.md#setting)", "no heading with anchor `#setting`"),
        (
            "![viewer](../images/viewer.png)",
            "image `../images/viewer.png`: images/viewer.png does not exist",
        ),
        ("[papers](../../shared/seeds/a.txt)", "leaves the repository"),
        ("[x](#nowhere)", "docs/guide.md has no heading with anchor `#nowhere`"),
        ("[x](methods/nirc.md#L3)", "no heading with anchor `#L3`"),
    ];
    for (link, expected) in cases {
        let text = format!("# Guide\n\nline two\n{link}\n");
        let errors = fixture_check("docs/guide.md", &text, &files);
        assert_eq!(errors.len(), 1, "{link}: {errors:?}");
        assert!(errors[0].starts_with("docs/guide.md:4: "), "{link}: {}", errors[0]);
        assert!(errors[0].contains(expected), "{link}: {}", errors[0]);
    }
}
