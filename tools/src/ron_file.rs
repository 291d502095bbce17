//! The RON of suite and sweep files, read one way: implicit `Some`, and every error a
//! `ScenarioError` at file:line:column, as scenario files report theirs. A list whose entries
//! are checked one by one (`cases`, `gates`, `grid`, `list`) stays raw in the file's struct,
//! and each entry is parsed where it stands ([`RonFile::entry`]), so its errors point at its
//! line too.

use std::path::Path;

use serde::de::DeserializeOwned;
use sim::scenario::{MethodEntry, ScenarioError, raw_entries};

/// A file's text and the path that names it in errors.
#[derive(Clone, Copy)]
pub struct RonFile<'a> {
    pub text: &'a str,
    pub origin: &'a Path,
}

/// The text of `path`, a `what` ("suite file") in the error when it cannot be read.
pub fn read(path: &Path, what: &str) -> Result<String, ScenarioError> {
    std::fs::read_to_string(path).map_err(|e| ScenarioError {
        file: path.to_path_buf(),
        position: None,
        message: format!("cannot read {what}: {e}"),
    })
}

fn options() -> ron::Options {
    ron::Options::default().with_default_extension(ron::extensions::Extensions::IMPLICIT_SOME)
}

impl RonFile<'_> {
    /// An error in this file, at a 1-based (line, column) when it has one.
    pub fn error(&self, position: Option<(usize, usize)>, message: String) -> ScenarioError {
        ScenarioError { file: self.origin.to_path_buf(), position, message }
    }

    /// An error about a whole entry, at its start.
    pub fn error_at(&self, entry: &MethodEntry, message: String) -> ScenarioError {
        self.error(Some((entry.line, entry.column)), message)
    }

    /// The whole file as `T`.
    pub fn parse<T: DeserializeOwned>(&self) -> Result<T, ScenarioError> {
        options().from_str(self.text).map_err(|e| {
            self.error(Some((e.span.start.line, e.span.start.col)), e.code.to_string())
        })
    }

    /// The entries of the raw list `raw` that follows `key`, each with its place in the file.
    pub fn entries(&self, key: &str, raw: &[Box<ron::value::RawValue>]) -> Vec<MethodEntry> {
        raw_entries(self.text, key, raw)
    }

    /// One entry as `T`; a position inside the entry is moved to the file's.
    pub fn entry<T: DeserializeOwned>(&self, entry: &MethodEntry) -> Result<T, ScenarioError> {
        options().from_str(&entry.text).map_err(|e| {
            let position = entry.position_in_file(e.span.start.line, e.span.start.col);
            self.error(Some(position), e.code.to_string())
        })
    }

    /// `name`, or else the file's stem, or else `fallback`.
    pub fn name_or_stem(&self, name: Option<String>, fallback: &str) -> String {
        name.unwrap_or_else(|| {
            self.origin
                .file_stem()
                .map(|s| s.to_string_lossy().into_owned())
                .unwrap_or_else(|| fallback.into())
        })
    }
}
