//! summary.json windows and means, charts and report.html from a fake run folder.

mod common;

use common::*;
use maud::html;
use metrics::frames_csv::Frames;
use report::run::{Manifest, Memory, MethodMemory};
use report::summary::{Summary, summarize};
use report::{page, table};

#[test]
fn summary_windows_and_means() {
    let tmp = fake_run("summary");
    let run = tmp.path().to_path_buf();
    report::write_summary_with_window(&run, 5).unwrap();
    let s = read_json(&run.join("summary.json"));
    let names: Vec<&str> =
        s["windows"].as_array().unwrap().iter().map(|w| w["name"].as_str().unwrap()).collect();
    assert_eq!(names, ["before_first_event", "after_event_0", "steady_after_event_0", "overall"]);
    let w = &s["windows"][1];
    assert_eq!((w["first"].as_u64(), w["last"].as_u64()), (Some(20), Some(24)));
    assert_eq!(s["windows"][2]["last"].as_u64(), Some(29));

    // Means are recomputed from frames.csv, independently of the summary code.
    let frames = Frames::load(&run).unwrap();
    let c = frames.column("smape").unwrap();
    for method in METHODS {
        let manual = |lo: u32, hi: u32| {
            let v: Vec<f64> = frames
                .rows
                .iter()
                .filter(|r| r.method == method && r.frame >= lo && r.frame <= hi)
                .filter_map(|r| r.values[c])
                .collect();
            v.iter().sum::<f64>() / v.len() as f64
        };
        let m = s["methods"].as_array().unwrap().iter().find(|m| m["method"] == method).unwrap();
        let before = m["means"]["before_first_event"]["smape"].as_f64().unwrap();
        let after = m["means"]["after_event_0"]["smape"].as_f64().unwrap();
        let steady = m["means"]["steady_after_event_0"]["smape"].as_f64().unwrap();
        assert!((before - manual(0, 19)).abs() < 1e-9);
        assert!((after - manual(20, 24)).abs() < 1e-9);
        assert!((steady - manual(25, 29)).abs() < 1e-9);
        // FLIP only on reference frames: before-window mean is frame 0's value.
        let f0 = frames.rows.iter().find(|r| r.method == method && r.frame == 0).unwrap().values
            [frames.column("flip").unwrap()]
        .unwrap();
        assert!((m["means"]["before_first_event"]["flip"].as_f64().unwrap() - f0).abs() < 1e-9);
    }
    // JOD where the window has reference frames (frames 0 and 20): a score out of 10 for each.
    for method in METHODS {
        let m = s["methods"].as_array().unwrap().iter().find(|m| m["method"] == method).unwrap();
        for w in ["before_first_event", "after_event_0", "overall"] {
            let jod = m["jod"][w].as_f64().unwrap_or_else(|| panic!("{method} {w}: {m}"));
            assert!(jod < 10.0 && jod > -5.0, "{method} {w}: {jod}");
        }
        assert!(m["jod"].get("steady_after_event_0").is_none(), "no reference there");
    }
    assert_eq!(s["cvvdp"]["display"], "standard_fhd");
    // The slowly adapting method flickers more right after the event than before it.
    let ema = s["methods"].as_array().unwrap().iter().find(|m| m["method"] == "cache_ema").unwrap();
    assert!(
        ema["means"]["after_event_0"]["smape"].as_f64().unwrap()
            > ema["means"]["before_first_event"]["smape"].as_f64().unwrap()
    );
}

#[test]
fn report_is_self_contained_with_charts_maps_and_crops() {
    let tmp = fake_run("report");
    let run = tmp.path().to_path_buf();
    let path = report::rebuild(&run, &[]).unwrap();
    assert_eq!(path, run.join("report.html"));
    let html = std::fs::read_to_string(&path).unwrap();
    for stem in [
        "frames_flip",
        "frames_smape",
        "frames_psnr",
        "frames_gpu_ms_total",
        "frames_steady_flip",
        "frames_changing_smape",
        "speed_vs_flip",
        "speed_vs_smape",
    ] {
        for ext in ["svg", "png"] {
            let f = run.join("charts").join(format!("{stem}.{ext}"));
            assert!(
                f.exists() && std::fs::metadata(&f).unwrap().len() > 500,
                "{} missing or empty",
                f.display()
            );
        }
    }
    // smape_reprojected has no data in this run: no chart for it.
    assert!(!run.join("charts/frames_smape_reprojected.svg").exists());
    for f in [
        "flip_pt_1spp_0020.png",
        "flip_cache_ema_0000.png",
        "crops_steady_0020.png",
        "crops_changing_0000.png",
    ] {
        assert!(run.join("charts").join(f).exists(), "{f}");
    }
    // Every image is inlined.
    let imgs = html.matches("<img ").count();
    assert_eq!(imgs, html.matches("src=\"data:image/").count());
    assert_eq!(
        imgs,
        14 + 2 * 2,
        "14 charts (7 metrics, 2 regions x 2, 2 speed, JOD per window and speed vs JOD); 2 region crops per reference frame"
    );
    for stem in ["windows_jod", "speed_vs_jod"] {
        assert!(run.join("charts").join(format!("{stem}.svg")).exists(), "{stem}");
    }
    // The viewer carries every frame once, FLIP maps where a reference exists.
    assert_eq!(html.matches("<script>flickerFrame(").count(), FRAMES as usize);
    assert_eq!(html.matches("\"flip:pt_1spp\"").count(), 2);
    // JOD: a table column, and a map of each scored frame in the viewer.
    assert!(html.contains("<th>JOD ↑</th>"), "no JOD column");
    assert_eq!(html.matches("\"jod:pt_1spp\"").count(), 2);
    assert!(html.contains("data-mode=\"jod\""));
    assert_eq!(html.matches("class=\"event-mark\"").count(), 1);
    assert!(!run.join("viewer").exists(), "a small run's frames are embedded, not linked");
    assert!(
        !html.contains("data-mode=\"motion\"") && html.contains("records no motion vectors"),
        "no motion toggle without motion vectors"
    );
    // The best method of each column is marked, once per column and window with data.
    // 3 windows (before, after the event, overall) x 7 columns with data (JOD, FLIP, SMAPE,
    // PSNR, rel. MSE, GPU ms, CPU ms): no ties in this run.
    assert_eq!(html.matches("class=\"best\"").count(), 3 * 7);
    // The cheaper method (1 ms against 2.5 ms) is marked in the GPU column of every window.
    let rows: Vec<&str> =
        html.split("<tr>").filter(|r| r.contains("<td class=\"m\">pt_1spp</td>")).collect();
    assert_eq!(rows.len(), 3);
    for r in rows {
        let cells: Vec<&str> = r.split("<td").collect();
        // window, frames, method, JOD, FLIP, SMAPE, PSNR, rel. MSE, GPU ms
        assert!(cells[9].starts_with(" class=\"best\""), "GPU ms cell of pt_1spp not marked: {r}");
    }
    // The Pareto chart comes before the summary table, the table before the frame charts.
    let at = |s: &str| html.find(s).unwrap_or_else(|| panic!("{s} missing"));
    assert!(
        at("id=\"viewer\"") < at("Speed vs accuracy")
            && at("Speed vs accuracy") < at("id=\"summary\"")
            && at("id=\"summary\"") < at("<h2>Charts")
    );
    assert!(html.contains("id=\"summary\"") && html.contains("rotate light"));
    // The event is drawn on the frame charts.
    let svg = std::fs::read_to_string(run.join("charts/frames_flip.svg")).unwrap();
    assert!(svg.contains("rotate light") && svg.contains("pt_1spp") && svg.contains("cache_ema"));
    if let Some(keep) = std::env::var_os("FLICKER_KEEP_REPORT") {
        std::fs::rename(&run, keep).unwrap();
    }
}

#[test]
fn minimal_run_without_reference_events_or_regions() {
    let tmp = tempfile::tempdir().unwrap();
    let run = tmp.path().to_path_buf();
    std::fs::create_dir_all(&run).unwrap();
    std::fs::write(run.join("manifest.json"), r#"{"scenario": "tiny", "methods": ["a"]}"#).unwrap();
    std::fs::write(
        run.join("frames.csv"),
        "method,frame,cpu_ms,smape\na,0,1.0,\na,1,1.2,0.5\na,2,1.1,0.25\n",
    )
    .unwrap();
    let html = std::fs::read_to_string(report::rebuild(&run, &[]).unwrap()).unwrap();
    let s = read_json(&run.join("summary.json"));
    let names: Vec<&str> =
        s["windows"].as_array().unwrap().iter().map(|w| w["name"].as_str().unwrap()).collect();
    assert_eq!(names, ["overall"]);
    assert_eq!(s["methods"][0]["means"]["overall"]["smape"].as_f64(), Some(0.375));
    assert!(
        run.join("charts/frames_smape.svg").exists()
            && run.join("charts/speed_vs_smape.png").exists()
    );
    assert_eq!(html.matches("<img ").count(), 3, "smape, cpu_ms, speed vs smape");
    // A malformed manifest is reported with its path.
    std::fs::write(run.join("manifest.json"), "{").unwrap();
    let err = format!("{:#}", report::rebuild(&run, &[]).unwrap_err());
    assert!(err.contains("manifest.json"), "{err}");
}

/// A name as it must stand in the markup: text or a double-quoted attribute value.
fn escaped(s: &str) -> String {
    s.replace('&', "&amp;").replace('<', "&lt;").replace('>', "&gt;").replace('"', "&quot;")
}

/// No hostile name, and none of their markup, is in `html` as it was written.
fn assert_no_raw_names(html: &str) {
    let names =
        HOSTILE_METHODS.iter().chain(&HOSTILE_REGIONS).chain([&HOSTILE_SCENARIO, &HOSTILE_EVENT]);
    for n in names {
        assert!(!html.contains(n), "{n} is in the page unescaped");
    }
    for markup in ["<img src=x", "<svg onload", "<!--", "</script><img", "</script><svg"] {
        assert!(!html.contains(markup), "{markup} is in the page");
    }
}

/// The viewer's JSON in its <script> elements: no `<` (no `</script>` or `<!--` can end or
/// change them), and the configuration reads back the panels' names as they were.
fn assert_script_json(html: &str, labels: &[String]) {
    let config = html
        .split("<script type=\"application/json\" id=\"flicker-config\">")
        .nth(1)
        .and_then(|s| s.split("</script>").next())
        .expect("no viewer configuration");
    let config: serde_json::Value = serde_json::from_str(config).unwrap();
    assert_eq!(config["labels"], serde_json::json!(labels));
    let chunks: Vec<&str> = html
        .split("<script>flickerFrame(")
        .skip(1)
        .map(|s| s.split("</script>").next().unwrap())
        .collect();
    assert!(!chunks.is_empty());
    for c in chunks {
        assert!(!c.contains('<'), "a frame's data holds `<`: {}", &c[..c.len().min(200)]);
        let json = c.split_once(',').unwrap().1.trim_end().trim_end_matches(");");
        let data: serde_json::Map<String, serde_json::Value> = serde_json::from_str(json).unwrap();
        assert!(
            data.keys().all(|k| labels.iter().any(|l| k.ends_with(l.as_str()))),
            "{:?}",
            data.keys()
        );
    }
}

#[test]
fn report_page_escapes_every_name_a_scenario_sets() {
    let tmp = hostile_run("hostile-report");
    let run = tmp.path().to_path_buf();
    let html = std::fs::read_to_string(report::rebuild(&run, &[]).unwrap()).unwrap();
    assert_no_raw_names(&html);
    let (scenario, event) = (escaped(HOSTILE_SCENARIO), escaped(HOSTILE_EVENT));
    let mut parts = vec![
        format!("<title>flicker run: {scenario}</title>"),
        format!("<h1>flicker run: {scenario}</h1>"),
        format!("<p>Events: frame 4: {event}</p>"),
        format!("title=\"frame 4: {event}\">▼</span>"),
        escaped(&format!("\"scenario\": \"{}\"", HOSTILE_SCENARIO.replace('"', "\\\""))),
    ];
    for m in HOSTILE_METHODS.map(escaped) {
        parts.push(format!("data-label=\"{m}\""));
        parts.push(format!("<figcaption>{m}<span class=\"value\"></span></figcaption>"));
        parts.push(format!("<td class=\"m\">{m}</td>"));
    }
    for r in HOSTILE_REGIONS.map(escaped) {
        parts.push(format!("alt=\"crops {r} frame 0\""));
        parts.push(format!("<figcaption>frame 4, {r}: reference, "));
    }
    for p in parts {
        assert!(html.contains(&p), "{p} is not in report.html");
    }
    let labels: Vec<String> =
        std::iter::once("reference").chain(HOSTILE_METHODS).map(String::from).collect();
    assert_script_json(&html, &labels);
}

#[test]
fn comparison_page_escapes_every_name_a_scenario_sets() {
    let (tmp_a, tmp_b) = (hostile_run("hostile-compare-a"), hostile_run("hostile-compare-b"));
    let (a, b) = (tmp_a.path(), tmp_b.path());
    let page = report::compare::write_comparison(a, b, &b.join("compare.html")).unwrap();
    let html = std::fs::read_to_string(page).unwrap();
    assert_no_raw_names(&html);
    let scenario = escaped(HOSTILE_SCENARIO);
    let mut parts = vec![format!("<td class=\"m\">{scenario}</td>")];
    for m in HOSTILE_METHODS.map(escaped) {
        parts.push(format!("data-label=\"A: {m}\""));
        parts.push(format!("<figcaption>B: {m}<span class=\"value\"></span></figcaption>"));
        parts.push(format!("<tr><td class=\"m\">{m}</td><td class=\"m\">FLIP</td>"));
    }
    for p in parts {
        assert!(html.contains(&p), "{p} is not in compare.html");
    }
    let mut labels = vec!["reference".to_string()];
    for m in HOSTILE_METHODS {
        labels.extend([format!("A: {m}"), format!("B: {m}")]);
    }
    assert_script_json(&html, &labels);
}

// The page builders, each with a name holding markup and quotes.

/// A method name as a scenario or a folder may set it: markup and quotes.
const HOSTILE_NAME: &str = "<img src=x onerror=alert(1)>\"'&";
const ESCAPED: &str = "&lt;img src=x onerror=alert(1)&gt;&quot;'&amp;";

/// Two methods, one with a hostile name, over 4 frames with an event at frame 2.
fn hostile_summary() -> (Summary, Frames) {
    let csv = format!(
        "method,frame,flip\n{HOSTILE_NAME},0,0.1\n{HOSTILE_NAME},3,0.2\npt,0,0.3\npt,3,0.4\n"
    );
    let frames = Frames::parse(&csv, std::path::Path::new("frames.csv")).unwrap();
    let manifest: Manifest = serde_json::from_value(serde_json::json!({
        "scenario": HOSTILE_NAME, "frames": 4, "events": [{"frame": 2, "label": HOSTILE_NAME}],
        "memory": {"methods": [{"label": HOSTILE_NAME, "device_bytes": 1048576}]}
    }))
    .unwrap();
    (summarize(&manifest, &frames, 1), frames)
}

/// The name is in the markup only escaped, as the text of a method cell.
fn assert_escaped(html: &str, cell: &str) {
    assert!(!html.contains("<img") && !html.contains(HOSTILE_NAME), "unescaped name: {html}");
    assert!(html.contains(&format!("<td class=\"m\">{cell}</td>")), "no escaped cell: {html}");
}

#[test]
fn the_summary_table_escapes_method_names() {
    let (summary, frames) = hostile_summary();
    let html = table::html(&summary, &frames).into_string();
    assert_escaped(&html, ESCAPED);
    assert_eq!(html.matches(ESCAPED).count(), summary.windows.len(), "{html}");
}

#[test]
fn the_memory_table_escapes_method_names() {
    let memory = Memory {
        methods: vec![MethodMemory { label: HOSTILE_NAME.into(), device_bytes: Some(1 << 20) }],
        ..Default::default()
    };
    let html = table::memory_html(&memory).into_string();
    assert_escaped(&html, &format!("device: {ESCAPED}"));
    assert!(html.contains("<td>1.00</td>"), "{html}");
}

#[test]
fn the_differences_table_escapes_method_names() {
    let (summary, frames) = hostile_summary();
    let html = table::differences_html(&summary, &summary, &frames, &frames).into_string();
    assert_escaped(&html, ESCAPED);
}

const HOSTILE_PAGE: &str = "<img src=x onerror=alert(1)>\"'&</script><!--";

#[test]
fn the_title_is_escaped_and_the_style_kept() {
    let page = page::document(HOSTILE_PAGE, "p>b{color:red}", html! { p { "body" } });
    assert!(page.starts_with("<!DOCTYPE html>\n<html lang=\"en\"><head><meta charset=\"utf-8\">"));
    assert!(
        page.contains(
            "<title>&lt;img src=x onerror=alert(1)&gt;&quot;'&amp;&lt;/script&gt;&lt;!--</title>"
        ),
        "{page}"
    );
    assert!(
        page.contains("<style>p>b{color:red}</style></head><body>\n<p>body</p></body></html>\n")
    );
    assert!(!page.contains("<img"), "{page}");
}

#[test]
fn json_in_a_script_cannot_close_it_and_reads_back_the_same() {
    let value = serde_json::json!({ "labels": [HOSTILE_PAGE], HOSTILE_PAGE: 1 });
    let text = page::script_json(&value).0;
    assert!(!text.contains('<'), "{text}");
    assert_eq!(serde_json::from_str::<serde_json::Value>(&text).unwrap(), value);
}
