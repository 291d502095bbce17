//! What the documentation tests share: which documents they read, and their Markdown parsed
//! by pulldown-cmark with GitHub's extensions (tables, strikethrough, task lists, footnotes).

#![allow(dead_code)] // each test file uses its own part

use std::path::{Path, PathBuf};

use pulldown_cmark::{Options, Parser};

/// The repository root (this package's folder).
pub fn root() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
}

/// One Markdown document: its path relative to the root, and its text.
pub struct Doc {
    pub path: PathBuf,
    pub text: String,
}

impl Doc {
    pub fn new(path: impl Into<PathBuf>, text: impl Into<String>) -> Doc {
        Doc { path: path.into(), text: text.into() }
    }

    /// 1-based line of byte offset `at`.
    pub fn line(&self, at: usize) -> usize {
        self.text[..at.min(self.text.len())].matches('\n').count() + 1
    }

    /// `path:line` of byte offset `at`, as errors name places.
    pub fn place(&self, at: usize) -> String {
        format!("{}:{}", self.path.display(), self.line(at))
    }

    /// The document's Markdown events with their byte ranges.
    pub fn events(
        &self,
    ) -> pulldown_cmark::OffsetIter<'_, pulldown_cmark::DefaultBrokenLinkCallback> {
        Parser::new_ext(&self.text, markdown_options()).into_offset_iter()
    }
}

/// GitHub-flavoured Markdown as pulldown-cmark has it.
pub fn markdown_options() -> Options {
    Options::ENABLE_TABLES
        | Options::ENABLE_STRIKETHROUGH
        | Options::ENABLE_TASKLISTS
        | Options::ENABLE_FOOTNOTES
}

/// The user documents the tests keep true: README.md, every Markdown file under docs/ (lab
/// notes included), and every crate's README.md (one or two folders down, outside target/ and
/// runs/).
pub fn documents() -> Vec<Doc> {
    let root = root();
    let mut paths = vec![PathBuf::from("README.md"), PathBuf::from("CONTRIBUTING.md")];
    markdown_under(&root, Path::new("docs"), &mut paths);
    for entry in read_dir_sorted(&root) {
        let name = entry.file_name().unwrap().to_string_lossy().into_owned();
        if !entry.is_dir()
            || name.starts_with('.')
            || ["docs", "target", "runs"].contains(&name.as_str())
        {
            continue;
        }
        let rel = PathBuf::from(&name);
        if root.join(&rel).join("README.md").is_file() {
            paths.push(rel.join("README.md"));
        }
        for sub in read_dir_sorted(&entry) {
            let sub_rel = rel.join(sub.file_name().unwrap());
            if sub.is_dir() && root.join(&sub_rel).join("README.md").is_file() {
                paths.push(sub_rel.join("README.md"));
            }
        }
    }
    paths
        .into_iter()
        .filter(|p| root.join(p).is_file())
        .map(|p| {
            let text = std::fs::read_to_string(root.join(&p))
                .unwrap_or_else(|e| panic!("{}: {e}", p.display()));
            Doc { path: p, text }
        })
        .collect()
}

fn read_dir_sorted(dir: &Path) -> Vec<PathBuf> {
    let mut out: Vec<PathBuf> = std::fs::read_dir(dir)
        .map(|r| r.filter_map(|e| e.ok().map(|e| e.path())).collect())
        .unwrap_or_default();
    out.sort();
    out
}

fn markdown_under(root: &Path, rel: &Path, out: &mut Vec<PathBuf>) {
    for entry in read_dir_sorted(&root.join(rel)) {
        let sub = rel.join(entry.file_name().unwrap());
        if entry.is_dir() {
            markdown_under(root, &sub, out);
        } else if sub.extension().is_some_and(|e| e == "md") {
            out.push(sub);
        }
    }
}
