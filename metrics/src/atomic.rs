//! Atomic writes: every file appears whole or not at all.
//!
//! A writer writes `NAME.tmpPID` beside the target and renames it into place, so an interrupted
//! run never leaves a truncated image, CSV or manifest behind. The one writer of the workspace:
//! `frame::output` (a run's files) and `report` (its pages and maps) sit above this crate.

use std::fs;
use std::io::{BufWriter, Write};
use std::path::{Path, PathBuf};

use anyhow::{Context, Result};

/// Writes what `write` produces to `path` through a temporary file and a rename.
pub fn write_atomic(path: &Path, write: impl FnOnce(&mut dyn Write) -> Result<()>) -> Result<()> {
    if let Some(dir) = path.parent().filter(|d| !d.as_os_str().is_empty()) {
        fs::create_dir_all(dir).with_context(|| format!("creating folder {}", dir.display()))?;
    }
    let tmp = tmp_path(path);
    let result = (|| {
        let file = fs::File::create(&tmp).with_context(|| format!("creating {}", tmp.display()))?;
        let mut out = BufWriter::new(file);
        write(&mut out)?;
        out.flush()?;
        out.into_inner().map_err(|e| e.into_error())?.sync_all()?;
        fs::rename(&tmp, path)
            .with_context(|| format!("renaming {} to {}", tmp.display(), path.display()))
    })();
    if result.is_err() {
        let _ = fs::remove_file(&tmp);
    }
    // A full disk fails a write or a flush, whose errors do not say which file.
    result.with_context(|| format!("cannot write {}", path.display()))
}

/// [`write_atomic`] of bytes already in memory.
pub fn write_bytes(path: &Path, bytes: impl AsRef<[u8]>) -> Result<()> {
    write_atomic(path, |w| Ok(w.write_all(bytes.as_ref())?))
}

/// The temporary file a write goes through before its rename.
pub fn tmp_path(path: &Path) -> PathBuf {
    // Per process: sweep jobs running side by side may store the same reference-cache entry.
    let mut name = path.file_name().unwrap_or_default().to_os_string();
    name.push(format!(".tmp{}", std::process::id()));
    path.with_file_name(name)
}
