//! docs/reproduce.md against the code: its table of rules is `judge::rules` row for row, and
//! its generated table (one `flicker reproduce all` run pasted between markers) names every
//! claim of claims/ with a verdict of today's vocabulary, and a single commit.

use std::path::{Path, PathBuf};

use tools::reproduce::Claims;
use tools::reproduce::judge::rules;
use tools::reproduce::verdict::VERDICTS;

fn root() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).parent().unwrap().to_path_buf()
}

fn page() -> String {
    std::fs::read_to_string(root().join("docs/reproduce.md")).unwrap()
}

/// The lines between `<!-- START` and `<!-- END` markers (the first pair).
fn between<'a>(text: &'a str, start: &str, end: &str) -> Vec<&'a str> {
    let lines: Vec<&str> = text.lines().collect();
    let a = lines.iter().position(|l| l.starts_with(start)).unwrap_or_else(|| {
        panic!("docs/reproduce.md has no line starting with '{start}'");
    });
    let b = a + lines[a..].iter().position(|l| l.starts_with(end)).unwrap_or_else(|| {
        panic!("docs/reproduce.md has no '{end}' after '{start}'");
    });
    lines[a + 1..b].to_vec()
}

/// A Markdown table row's cells, backticks and escapes removed.
fn cells(row: &str) -> Vec<String> {
    let inner = row.trim().trim_start_matches('|').trim_end_matches('|');
    let mut out = vec![String::new()];
    let mut chars = inner.chars().peekable();
    while let Some(c) = chars.next() {
        match c {
            '\\' if chars.peek() == Some(&'|') => {
                out.last_mut().unwrap().push(chars.next().unwrap())
            }
            '|' => out.push(String::new()),
            c => out.last_mut().unwrap().push(c),
        }
    }
    out.iter().map(|c| c.trim().replace('`', "")).collect()
}

#[test]
fn the_docs_table_of_rules_is_the_codes() {
    let page = page();
    let table = between(&page, "<!-- rules: tools::reproduce::judge::rules", "<!-- end rules");
    assert_eq!(
        cells(table[0]),
        [
            "comparison",
            "per-seed effect",
            "the paper's region",
            "reproduced",
            "not reproduced",
            "inconclusive"
        ]
    );
    let docs: Vec<Vec<String>> = table[2..].iter().map(|r| cells(r)).collect();
    let code: Vec<Vec<String>> = rules()
        .iter()
        .map(|r| {
            [r.comparison, r.effect, r.region, r.reproduced, r.not_reproduced, r.inconclusive]
                .iter()
                .map(|s| s.to_string())
                .collect()
        })
        .collect();
    assert_eq!(docs, code, "docs/reproduce.md's table of rules differs from judge::rules()");
}

/// Every claim id of the shipped claims files.
fn claim_ids() -> Vec<String> {
    let mut ids = Vec::new();
    for entry in std::fs::read_dir(root().join("claims")).unwrap() {
        let path = entry.unwrap().path();
        if path.extension().is_some_and(|e| e == "ron") {
            let c = Claims::load(&path).unwrap();
            ids.extend(c.claims.iter().map(|claim| claim.id.clone()));
        }
    }
    ids
}

/// Words of 7 to 40 hex digits with a digit and a letter: commit hashes, possibly abbreviated.
fn commits(text: &str) -> Vec<String> {
    let mut found: Vec<String> = text
        .split(|c: char| !c.is_ascii_alphanumeric())
        .filter(|w| (7..=40).contains(&w.len()))
        .filter(|w| w.chars().all(|c| c.is_ascii_digit() || ('a'..='f').contains(&c)))
        .filter(|w| w.chars().any(|c| c.is_ascii_digit()) && w.chars().any(|c| c.is_alphabetic()))
        .map(str::to_string)
        .collect();
    found.sort();
    found.dedup();
    // An abbreviation of a named full hash is the same commit.
    let full: Vec<String> = found.iter().filter(|w| w.len() == 40).cloned().collect();
    found.retain(|w| w.len() == 40 || !full.iter().any(|f| f.starts_with(w.as_str())));
    found
}

#[test]
fn the_generated_table_has_every_claim_with_a_verdict_at_one_commit() {
    let page = page();
    let generated = between(&page, "<!-- generated: flicker reproduce all", "<!-- end generated");
    let named = commits(&page);
    let text: Vec<&str> = generated.iter().map(|l| l.trim()).filter(|l| !l.is_empty()).collect();
    if text == ["Not yet run at one commit."] {
        // No table yet: then no row and no commit may pretend there is one.
        assert!(named.is_empty(), "docs/reproduce.md names commits {named:?} but no run");
        assert!(
            !page.lines().any(|l| claim_ids().iter().any(|id| l.starts_with(&format!("| {id}: "))))
        );
        return;
    }
    for id in claim_ids() {
        let prefix = format!("| {id}: ");
        let row = generated.iter().find(|l| l.starts_with(&prefix)).unwrap_or_else(|| {
            panic!("claim '{id}' has no row in docs/reproduce.md's generated table")
        });
        let verdict = &cells(row)[5];
        assert!(
            VERDICTS.iter().any(|v| verdict == v
                || verdict.starts_with(&format!("{v} ("))
                || verdict.starts_with(&format!("{v}:"))),
            "claim '{id}': verdict '{verdict}' is none of {VERDICTS:?}"
        );
    }
    assert_eq!(named.len(), 1, "docs/reproduce.md names commits {named:?}; expected one");
    assert!(
        generated.iter().any(|l| l.contains(&format!("commit {}", named[0]))),
        "the generated table is stamped with the commit"
    );
    assert!(!page.contains(&format!("{}-dirty", named[0])), "a run from a dirty checkout");
}

#[test]
fn commits_are_found_and_abbreviations_counted_once() {
    let full = "0123456789abcdef0123456789abcdef01234567";
    assert_eq!(commits(&format!("at commit {full}, see 0123456 and deadbee1")).len(), 2);
    assert_eq!(commits(&format!("commit {full} (0123456)")), [full]);
    assert!(commits("no hashes: reproduced, 1280x720, decade").is_empty());
}

/// A verdict comes from one commit and one place: the method pages (docs/methods/) hold no
/// table of claims or verdicts of their own, and a page that names a paper's `flicker
/// reproduce` links to that paper's part of the generated table (docs_links checks the anchor).
#[test]
fn method_pages_leave_verdicts_to_the_generated_table() {
    let ids = claim_ids();
    let papers: Vec<String> = std::fs::read_dir(root().join("claims"))
        .unwrap()
        .map(|e| e.unwrap().path())
        .filter(|p| p.extension().is_some_and(|e| e == "ron"))
        .map(|p| p.file_stem().unwrap().to_str().unwrap().to_string())
        .collect();
    let dir = root().join("docs/methods");
    let mut pages = 0;
    for entry in std::fs::read_dir(&dir).unwrap() {
        let path = entry.unwrap().path();
        if path.extension().is_none_or(|e| e != "md") {
            continue;
        }
        pages += 1;
        let text = std::fs::read_to_string(&path).unwrap();
        let name = path.strip_prefix(root()).unwrap().display().to_string();
        for (n, line) in text.lines().enumerate().filter(|(_, l)| l.trim_start().starts_with('|')) {
            let row = cells(line);
            assert!(
                !row.iter().any(|c| c.eq_ignore_ascii_case("verdict")),
                "{name}:{}: a table with a verdict column; link the paper's part of docs/reproduce.md's generated table instead",
                n + 1
            );
            assert!(
                !ids.contains(&row[0]),
                "{name}:{}: a row for claim '{}'; its verdict and numbers belong to docs/reproduce.md's generated table",
                n + 1,
                row[0]
            );
        }
        for paper in &papers {
            if text.contains(&format!("flicker reproduce {paper}")) {
                assert!(
                    text.contains(&format!("../reproduce.md#{paper})")),
                    "{name} plays `flicker reproduce {paper}` but does not link ../reproduce.md#{paper}"
                );
            }
        }
    }
    assert!(pages >= 5, "{pages} method pages in {}", dir.display());
}
