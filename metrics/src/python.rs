//! The Python interpreter that runs the independent programs (NVIDIA's FLIP, Mitsuba 3, the
//! walk-through's scripts): one rule for every caller, so that a test and the bench use the
//! same one.

use std::path::PathBuf;

/// `$FLICKER_PYTHON` if set; else the checkout's `.venv/bin/python3` that
/// scripts/setup-tests.sh makes (pinned versions), where it exists; else `python3` on PATH.
pub fn interpreter() -> PathBuf {
    if let Some(p) = std::env::var_os("FLICKER_PYTHON").filter(|p| !p.is_empty()) {
        return PathBuf::from(p);
    }
    let venv = checkout_venv().join("bin").join("python3");
    if venv.exists() { venv } else { PathBuf::from("python3") }
}

/// The checkout's `.venv` (beside the workspace's Cargo.toml), whether or not it exists.
pub fn checkout_venv() -> PathBuf {
    PathBuf::from(concat!(env!("CARGO_MANIFEST_DIR"), "/../.venv"))
}

/// PATH with the interpreter's folder first, for scripts that call `python3` by name (the
/// walk-through's commands), so that they run the same Python as [`interpreter`].
pub fn path_with_interpreter() -> std::ffi::OsString {
    let path = std::env::var_os("PATH").unwrap_or_default();
    let python = interpreter();
    let Some(dir) = python.parent().filter(|d| !d.as_os_str().is_empty()) else { return path };
    let mut dirs = vec![dir.to_path_buf()];
    dirs.extend(std::env::split_paths(&path));
    std::env::join_paths(dirs).unwrap_or(path)
}
