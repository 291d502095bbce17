//! XDG_RUNTIME_DIR for the graphics stack. Mesa's Vulkan drivers load libwayland, which prints
//! "error: XDG_RUNTIME_DIR is invalid or not set in the environment." (twice) when the variable
//! is unset or not an absolute path, as on a root shell or in CI. The message is harmless but
//! reads as a failure, so when the variable is unusable it is pointed at a private folder first.

use std::path::{Path, PathBuf};

/// Whether `dir` is usable as XDG_RUNTIME_DIR: an absolute path to an existing folder (the XDG
/// base directory spec also asks for owner-only access, which libwayland does not check).
pub fn usable(dir: &Path) -> bool {
    dir.is_absolute() && dir.is_dir()
}

/// `$TMPDIR/flicker-runtime-UID`, created with owner-only access.
fn private_dir() -> std::io::Result<PathBuf> {
    use std::os::unix::fs::{DirBuilderExt, MetadataExt, PermissionsExt};
    let uid = std::fs::metadata("/proc/self").map(|m| m.uid()).unwrap_or(0);
    let dir = std::env::temp_dir().join(format!("flicker-runtime-{uid}"));
    std::fs::DirBuilder::new().recursive(true).mode(0o700).create(&dir)?;
    let meta = std::fs::metadata(&dir)?;
    if meta.uid() != uid {
        return Err(std::io::Error::other(format!("{} belongs to another user", dir.display())));
    }
    std::fs::set_permissions(&dir, std::fs::Permissions::from_mode(0o700))?;
    Ok(dir)
}

/// Points XDG_RUNTIME_DIR at a private folder when it is unset or unusable. Call first in
/// `main`, before any thread starts (changing the environment is only sound then).
pub fn ensure() {
    if std::env::var_os("XDG_RUNTIME_DIR").is_some_and(|d| usable(Path::new(&d))) {
        return;
    }
    match private_dir() {
        // SAFETY: called at the start of main, while the program has a single thread.
        Ok(dir) => unsafe { std::env::set_var("XDG_RUNTIME_DIR", dir) },
        Err(e) => eprintln!(
            "note: XDG_RUNTIME_DIR is unset and no private folder could be made ({e}); a message about it from the graphics drivers is harmless"
        ),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn relative_or_missing_folders_are_not_usable() {
        assert!(!usable(Path::new("relative/run")));
        assert!(!usable(Path::new("/no/such/folder/flicker")));
        assert!(usable(&std::env::temp_dir()));
        let d = private_dir().unwrap();
        assert!(usable(&d));
        use std::os::unix::fs::PermissionsExt;
        assert_eq!(std::fs::metadata(&d).unwrap().permissions().mode() & 0o777, 0o700);
    }
}
