//! Headless Chromium for the report tests. A missing browser fails the test that asks for it:
//! a report is never reported as checked when it was not.

use std::path::{Path, PathBuf};
use std::process::Command;
use std::sync::atomic::{AtomicUsize, Ordering};

pub fn chromium() -> PathBuf {
    ["chromium", "chromium-browser", "google-chrome"]
        .into_iter()
        .find(|c| Command::new(c).arg("--version").output().is_ok_and(|o| o.status.success()))
        .map(PathBuf::from)
        .expect("chromium not found (run scripts/setup-tests.sh, or apt-get install chromium)")
}

/// Inserted first in <head>: records console errors, uncaught exceptions and failed resource
/// loads (chromium's log does not tell console levels apart).
pub const ERROR_HOOK: &str = r#"<script>
window.__errors = [];
const __origError = console.error;
console.error = (...a) => { window.__errors.push('console.error: ' + a.join(' ')); __origError(...a); };
window.addEventListener('error', e => window.__errors.push('error: ' + (e.message || (e.target && e.target.tagName))), true);
window.addEventListener('unhandledrejection', e => window.__errors.push('unhandled rejection: ' + e.reason));
</script>"#;

/// Window size of every run, so that a layout measured in one run holds in another.
pub const WINDOW: (u32, u32) = (1400, 1000);

/// Runs headless Chromium on `url` (a file:// URL, maybe with a #fragment) with `extra` flags;
/// timers run in virtual time, up to 10 s of it.
pub fn browser(bin: &Path, work: &Path, extra: &[String], url: &str) -> std::process::Output {
    static PROFILE: AtomicUsize = AtomicUsize::new(0);
    let profile = work.join(format!("profile-{}", PROFILE.fetch_add(1, Ordering::Relaxed)));
    let _ = std::fs::remove_dir_all(&profile);
    Command::new(bin)
        .args([
            "--headless",
            "--no-sandbox",
            "--disable-gpu",
            "--disable-background-networking",
            "--disable-component-update",
            "--disable-sync",
            "--no-first-run",
            "--hide-scrollbars",
            "--force-device-scale-factor=1",
            "--enable-logging=stderr",
            "--v=0",
            "--virtual-time-budget=10000",
        ])
        .arg(format!("--window-size={},{}", WINDOW.0, WINDOW.1))
        .arg(format!("--user-data-dir={}", profile.display()))
        .args(extra)
        .arg(url)
        .output()
        .expect("run chromium")
}

pub fn file_url(page: &Path) -> String {
    format!("file://{}", page.display())
}

/// The text of the element with `id` in a --dump-dom output, unescaped.
pub fn element_text(dom: &str, id: &str) -> Option<String> {
    let start = dom.split(&format!("id=\"{id}\">")).nth(1)?;
    let text = start.split('<').next()?;
    Some(
        text.replace("&lt;", "<")
            .replace("&gt;", ">")
            .replace("&quot;", "\"")
            .replace("&#39;", "'")
            .replace("&amp;", "&"),
    )
}
