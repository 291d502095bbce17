//! The reference cache's entry lock survives a killed holder: a child process takes the lock
//! of an entry and is killed with SIGKILL (no destructor runs); the lock file stays, and the
//! next run takes the lock at once instead of waiting for a holder that is gone.

use std::path::Path;

use frame::reference_cache::ReferenceCache;

/// Not a test: the child process of `a_killed_holder_releases_its_lock`, which holds the
/// lock of entry `k` in `$FLICKER_LOCK_HOLDER_DIR` until it is killed.
#[test]
#[ignore = "run by a_killed_holder_releases_its_lock as its child"]
fn lock_holder() {
    let dir = std::env::var_os("FLICKER_LOCK_HOLDER_DIR").expect("run as a child");
    let cache = ReferenceCache::new(&dir);
    let _lock = cache.lock("k", || panic!("nobody else holds it")).unwrap();
    std::fs::write(Path::new(&dir).join("held"), b"").unwrap();
    std::thread::sleep(std::time::Duration::from_secs(120));
}

#[test]
fn a_killed_holder_releases_its_lock() {
    let tmp = tempfile::tempdir().unwrap();
    let dir = tmp.path();
    let mut child = std::process::Command::new(std::env::current_exe().unwrap())
        .args(["lock_holder", "--exact", "--ignored", "--nocapture"])
        .env("FLICKER_LOCK_HOLDER_DIR", dir)
        .spawn()
        .unwrap();
    let started = std::time::Instant::now();
    while !dir.join("held").exists() {
        assert!(started.elapsed().as_secs() < 60, "the child never took the lock");
        assert!(child.try_wait().unwrap().is_none(), "the child ended");
        std::thread::sleep(std::time::Duration::from_millis(20));
    }
    let cache = ReferenceCache::new(dir);
    let other = std::fs::OpenOptions::new().write(true).open(cache.lock_path("k")).unwrap();
    assert!(
        matches!(other.try_lock(), Err(std::fs::TryLockError::WouldBlock)),
        "the living holder's lock must exclude others"
    );
    child.kill().unwrap(); // SIGKILL: no destructor, no clean-up of its own
    child.wait().unwrap();
    // The lock file stays, but the OS released the lock with its holder.
    assert!(cache.lock_path("k").exists());
    let _lock =
        cache.lock("k", || panic!("a killed holder's lock must not be waited for")).unwrap();
    drop(other);
}
