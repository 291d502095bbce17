//! Names a scenario sets (its name, a region, a glTF entity that an event moves), holding markup
//! and quotes, played for real and read back from report.html's DOM in headless Chromium: each
//! is text where it appears, nothing it holds became an element or ran.

#[path = "../report/tests/common/browser.rs"]
mod browser;

use std::path::PathBuf;
use std::process::Command;

use browser::{ERROR_HOOK, browser, chromium, element_text, file_url};

const SCENARIO: &str = "</script><img src=x onerror=alert(1)>\"'&";
const REGION: &str = "<img src=x onerror=alert(2)>\"'&";
const ENTITY: &str = "<!--<script>\"'&";

/// Records alert() calls (an injected handler would make one), before the page's own scripts.
const ALERT_HOOK: &str =
    "<script>window.__alerts = []; window.alert = m => window.__alerts.push(String(m));</script>";

/// After load: where the names should be, and every element they could have made.
const CHECK: &str = r#"<script>
window.addEventListener('load', async () => {
  const out = {};
  try {
    const all = s => Array.from(document.querySelectorAll(s));
    out.handlers = all('*').filter(e => Array.from(e.attributes).some(a => a.name.startsWith('on'))).length;
    out.injected = all('img:not([src^="data:"]), svg').length;
    out.broken = all('img').filter(i => !(i.complete && i.naturalWidth > 0)).map(i => i.alt);
    out.h1 = document.querySelector('h1').textContent;
    out.marks = all('.event-mark').map(m => m.title);
    out.crops = all('img.crop').map(i => i.alt);
    out.manifest = all('pre')[0].textContent;
    await window.flickerViewer.whenShown();
    out.labels = window.flickerViewer.labels;
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

/// `s` inside a RON or JSON string literal.
fn quoted(s: &str) -> String {
    serde_json::to_string(s).unwrap()
}

#[test]
fn a_played_scenario_with_markup_in_its_names_reports_them_as_text() {
    let bin = chromium();
    let tmp = tempfile::Builder::new().prefix("flicker-report-names-").tempdir().unwrap();
    let dir = tmp.path().to_path_buf();
    // The test asset with its cube (mesh and node) renamed.
    let root = PathBuf::from(env!("CARGO_MANIFEST_DIR"));
    let gltf = std::fs::read_to_string(root.join("scenarios/assets/test_scene.gltf")).unwrap();
    assert_eq!(gltf.matches("\"name\": \"Cube\"").count(), 2, "the asset changed");
    let gltf = gltf.replace("\"name\": \"Cube\"", &format!("\"name\": {}", quoted(ENTITY)));
    std::fs::write(dir.join("scene.gltf"), gltf).unwrap();
    let scenario = dir.join("names.ron");
    std::fs::write(
        &scenario,
        format!(
            "Scenario(name: {}, scene: Gltf(\"scene.gltf\"), resolution: (16, 9), frames: 3, seed: 1,
                methods: [PathTracing(spp: 1)], reference: (spp: 4, frames: List([2])),
                regions: [(name: {}, x: 0, y: 0, w: 8, h: 8)],
                events: [(frame: 1, action: MoveBy(entity: {}, offset: (0.0, 0.1, 0.0)))])",
            quoted(SCENARIO),
            quoted(REGION),
            quoted(ENTITY)
        ),
    )
    .unwrap();
    let out = dir.join("run");
    let o = Command::new(env!("CARGO_BIN_EXE_flicker"))
        .args(["run", scenario.to_str().unwrap(), "--quiet", "--out", out.to_str().unwrap()])
        .args(["--cache-dir", dir.join("cache").to_str().unwrap()])
        .output()
        .unwrap();
    assert!(o.status.success(), "the run failed: {}", String::from_utf8_lossy(&o.stderr));

    let html = std::fs::read_to_string(out.join("report.html")).unwrap();
    let page = dir.join("checked.html");
    std::fs::write(
        &page,
        html.replacen("<head>", &format!("<head>{ALERT_HOOK}{ERROR_HOOK}"), 1).replacen(
            "</body>",
            &format!("{CHECK}</body>"),
            1,
        ),
    )
    .unwrap();
    let o = browser(&bin, &dir, &["--dump-dom".into()], &file_url(&page));
    let dom = String::from_utf8_lossy(&o.stdout);
    let text = element_text(&dom, "names-check").unwrap_or_else(|| {
        panic!(
            "the check did not run (a name changed the page's markup?): {}",
            String::from_utf8_lossy(&o.stderr)
        )
    });
    let seen: serde_json::Value = serde_json::from_str(&text).unwrap();
    assert!(seen.get("error").is_none(), "script error: {}", seen["error"]);
    assert_eq!(seen["alerts"], serde_json::json!([]), "a name's markup ran");
    assert_eq!((seen["handlers"].as_u64(), seen["injected"].as_u64()), (Some(0), Some(0)));
    assert_eq!(seen["errors"], serde_json::json!([]), "console errors");
    assert_eq!(seen["broken"], serde_json::json!([]), "images (charts with the names) not decoded");
    assert_eq!(seen["h1"], format!("flicker run: {SCENARIO}"));
    let marks = seen["marks"].as_array().unwrap();
    assert!(
        marks.len() == 1 && marks[0].as_str().unwrap().contains(&format!("'{ENTITY}'")),
        "{marks:?}"
    );
    assert_eq!(seen["crops"], serde_json::json!([format!("crops {REGION} frame 2")]));
    assert_eq!(seen["labels"], serde_json::json!(["reference", "pt_1spp"]));
    let manifest: serde_json::Value =
        serde_json::from_str(seen["manifest"].as_str().unwrap()).unwrap();
    assert_eq!(
        (manifest["scenario"].as_str(), manifest["regions"][0]["name"].as_str()),
        (Some(SCENARIO), Some(REGION))
    );
}
