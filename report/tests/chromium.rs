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
    let report = report::rebuild(&run, &[]).unwrap();
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

/// Inserted first in <head>: records every alert() (an injected handler would call it).
const ALERT_HOOK: &str =
    "<script>window.__alerts = []; window.alert = m => window.__alerts.push(String(m));</script>";

/// Appended to the page: after load (and the viewer's first frame), what the DOM holds where
/// the scenario's names go, and every element with an event-handler attribute.
const NAMES_SCRIPT: &str = r#"<script>
window.addEventListener('load', async () => {
  const out = {};
  try {
    const all = s => Array.from(document.querySelectorAll(s));
    out.handlers = all('*').filter(e => Array.from(e.attributes).some(a => a.name.startsWith('on'))).map(e => e.outerHTML.slice(0, 120));
    out.injected = all('img:not([src^="data:"]), svg').length;
    out.broken = all('img').filter(i => !(i.complete && i.naturalWidth > 0)).map(i => i.alt);
    out.title = document.title;
    out.h1 = document.querySelector('h1').textContent;
    out.panels = all('#panels figure').map(f => f.dataset.label);
    out.captions = all('#panels figcaption').map(f => f.firstChild.textContent);
    out.marks = all('.event-mark').map(m => m.title);
    out.methodCells = all('#summary td.m, #differences td.m, #runs td.m').map(td => td.textContent);
    out.crops = all('img.crop').map(i => i.alt);
    out.manifest = (all('pre')[0] || {}).textContent;
    await window.flickerViewer.whenShown();
    out.labels = window.flickerViewer.labels;
    out.shown = window.flickerViewer.state.shown;
  } catch (e) {
    out.error = String((e && e.stack) || e);
  }
  out.alerts = window.__alerts;
  out.errors = window.__errors;
  const d = document.createElement('div');
  d.id = 'names-check';
  d.textContent = JSON.stringify(out);
  document.body.appendChild(d);
});
</script>"#;

/// Opens `page` with the hooks and the names script; returns what the script saw.
fn names_in_dom(bin: &Path, work: &Path, page: &Path) -> serde_json::Value {
    let html = std::fs::read_to_string(page).unwrap();
    let checked = work.join(format!("names-{}", page.file_name().unwrap().to_str().unwrap()));
    let with_check = html
        .replacen("<head>", &format!("<head>{ALERT_HOOK}{ERROR_HOOK}"), 1)
        .replacen("</body>", &format!("{NAMES_SCRIPT}</body>"), 1);
    std::fs::write(&checked, with_check).unwrap();
    let out = browser(bin, work, &["--dump-dom".into()], &file_url(&checked));
    let dom = String::from_utf8_lossy(&out.stdout);
    let text = element_text(&dom, "names-check").unwrap_or_else(|| {
        panic!(
            "{}: the names script did not run (the page's markup was changed by a name?); stderr:\n{}",
            page.display(),
            String::from_utf8_lossy(&out.stderr)
        )
    });
    serde_json::from_str(&text).unwrap()
}

/// Nothing a name held ran or became an element, and the page's own script worked.
fn assert_inert(out: &serde_json::Value) {
    assert!(out.get("error").is_none(), "script error: {}", out["error"]);
    assert_eq!(out["alerts"], serde_json::json!([]), "a name's markup ran");
    assert_eq!(out["handlers"], serde_json::json!([]), "elements with handlers");
    assert_eq!(out["injected"], 0, "an image or SVG that is not the page's");
    assert_eq!(out["broken"], serde_json::json!([]), "images (charts with the names) not decoded");
    assert_eq!(out["errors"], serde_json::json!([]), "console errors");
}

#[test]
fn names_with_markup_and_quotes_are_text_in_report_and_comparison() {
    use common::{HOSTILE_EVENT, HOSTILE_METHODS, HOSTILE_REGIONS, HOSTILE_SCENARIO};
    let bin = chromium();
    let a_tmp = common::hostile_run("names-a");
    let a = a_tmp.path();
    let work = a.join("browser");
    std::fs::create_dir_all(&work).unwrap();

    let out = names_in_dom(&bin, &work, &report::rebuild(a, &[]).unwrap());
    assert_inert(&out);
    let title = format!("flicker run: {HOSTILE_SCENARIO}");
    assert_eq!((out["title"].as_str(), out["h1"].as_str()), (Some(&*title), Some(&*title)));
    let panels: Vec<&str> = std::iter::once("reference").chain(HOSTILE_METHODS).collect();
    for key in ["panels", "captions", "labels"] {
        assert_eq!(out[key], serde_json::json!(panels), "{key}");
    }
    assert_eq!(out["marks"], serde_json::json!([format!("frame 4: {HOSTILE_EVENT}")]));
    for m in HOSTILE_METHODS {
        assert!(out["methodCells"].as_array().unwrap().iter().any(|c| c == m), "{m}");
    }
    for r in HOSTILE_REGIONS {
        assert!(out["crops"].as_array().unwrap().contains(&format!("crops {r} frame 0").into()));
    }
    let manifest: serde_json::Value =
        serde_json::from_str(out["manifest"].as_str().unwrap()).unwrap();
    assert_eq!(manifest["scenario"], HOSTILE_SCENARIO);
    assert_eq!(out["shown"], 4, "the viewer opens on the event");

    let b_tmp = common::hostile_run("names-b");
    let page =
        report::compare::write_comparison(a, b_tmp.path(), &work.join("compare.html")).unwrap();
    let out = names_in_dom(&bin, &work, &page);
    assert_inert(&out);
    let mut panels = vec!["reference".to_string()];
    for m in HOSTILE_METHODS {
        panels.extend([format!("A: {m}"), format!("B: {m}")]);
    }
    for key in ["panels", "captions", "labels"] {
        assert_eq!(out[key], serde_json::json!(panels), "{key}");
    }
    assert!(out["methodCells"].as_array().unwrap().contains(&HOSTILE_SCENARIO.into()));
}
