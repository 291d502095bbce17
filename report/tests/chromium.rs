//! report.html in a real headless Chromium (Debian's `chromium`): it loads without console
//! errors, and every image and chart is decoded and laid out with a non-zero size; a screenshot
//! is not blank. Control pages with a broken image and a console error prove the checks can fail.

mod common;

use std::path::Path;

use common::browser::{ERROR_HOOK, browser, chromium, element_text, file_url};

/// Appended to the page: after load, reports how many images are not displayed.
const CHECK_SCRIPT: &str = r#"<script>
window.addEventListener('load', () => {
  const bad = [];
  const imgs = Array.from(document.images);
  for (const img of imgs) {
    const r = img.getBoundingClientRect();
    if (!(img.complete && img.naturalWidth > 0 && img.naturalHeight > 0 && r.width > 0 && r.height > 0)) bad.push(img.alt);
  }
  const d = document.createElement('div');
  d.id = 'flicker-check';
  d.textContent = 'IMAGES ' + imgs.length + ' BAD ' + bad.length + ' ERRORS ' + window.__errors.length + ' [' + bad.join('|') + '] [' + window.__errors.join('|') + ']';
  document.body.appendChild(d);
});
</script>"#;

struct Outcome {
    images: usize,
    bad: usize,
    console_errors: Vec<String>,
}

fn check_page(bin: &Path, work: &Path, html: &str, name: &str) -> Outcome {
    let page = work.join(name);
    let with_check = html.replacen("<head>", &format!("<head>{ERROR_HOOK}"), 1).replacen(
        "</body>",
        &format!("{CHECK_SCRIPT}</body>"),
        1,
    );
    std::fs::write(&page, with_check).unwrap();
    let out = browser(bin, work, &["--dump-dom".into()], &file_url(&page));
    let dom = String::from_utf8_lossy(&out.stdout);
    let stderr = String::from_utf8_lossy(&out.stderr);
    let line = element_text(&dom, "flicker-check").unwrap_or_else(|| {
        panic!(
            "{name}: the check did not run; chromium stdout tail:\n{}\nstderr:\n{stderr}",
            &dom[dom.len().saturating_sub(500)..]
        )
    });
    let words: Vec<&str> = line.split_whitespace().collect();
    let hooked: usize = words[5].parse().unwrap();
    let mut console_errors: Vec<String> = stderr
        .lines()
        .filter(|l| l.contains("CONSOLE") && l.contains("Uncaught"))
        .map(str::to_string)
        .collect();
    if hooked > 0 {
        console_errors.push(line.clone());
    }
    Outcome { images: words[1].parse().unwrap(), bad: words[3].parse().unwrap(), console_errors }
}

#[test]
fn report_displays_every_image_without_console_errors() {
    let bin = chromium();
    let tmp = common::fake_run("chromium");
    let run = tmp.path().to_path_buf();
    let report = report::rebuild(&run).unwrap();
    let html = std::fs::read_to_string(&report).unwrap();
    let work = run.join("browser");
    std::fs::create_dir_all(&work).unwrap();

    let ok = check_page(&bin, &work, &html, "report.html");
    assert_eq!(
        ok.images,
        html.matches("<img ").count(),
        "every <img> of the report is seen by the browser"
    );
    assert!(ok.images >= 16, "12 charts and 4 region crops");
    assert_eq!(ok.bad, 0, "images not displayed");
    assert!(ok.console_errors.is_empty(), "console errors: {:?}", ok.console_errors);

    // Controls: a broken image and a console error must be caught.
    let broken =
        html.replacen("<img ", "<img alt=\"broken\" src=\"data:image/png;base64,AAAA\" data-x=", 1);
    assert_eq!(check_page(&bin, &work, &broken, "broken.html").bad, 1);
    let noisy = html.replacen("</body>", "<script>console.error('boom')</script></body>", 1);
    let thrown = html.replacen("</body>", "<script>undefined_function()</script></body>", 1);
    assert!(
        !check_page(&bin, &work, &thrown, "thrown.html").console_errors.is_empty(),
        "exceptions must be detected"
    );
    assert!(
        !check_page(&bin, &work, &noisy, "noisy.html").console_errors.is_empty(),
        "console.error must be detected"
    );

    // The rendered page is not blank: its screenshot has plenty of non-white pixels.
    let shot = work.join("shot.png");
    let out =
        browser(&bin, &work, &[format!("--screenshot={}", shot.display())], &file_url(&report));
    assert!(shot.exists(), "no screenshot: {}", String::from_utf8_lossy(&out.stderr));
    let img = image::open(&shot).unwrap().to_rgb8();
    let inked = img.pixels().filter(|p| p.0.iter().any(|&c| c < 200)).count();
    assert!(
        inked as f64 > 0.01 * (img.width() * img.height()) as f64,
        "screenshot mostly blank ({inked} inked pixels)"
    );
}
