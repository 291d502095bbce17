//! The viewer of report.html, driven in headless Chromium by a script run in the page: real
//! input, click, wheel and pointer events, results written into the DOM and read from
//! --dump-dom. Screenshots at two frames differ where the scene changes and only there.

mod common;

use std::path::Path;

use common::browser::{ERROR_HOOK, WINDOW, browser, chromium, element_text, file_url};
use common::*;
use metrics::{DEFAULT_PPD, flip_hdr, load_image, smape};
use serde_json::Value;

/// Frames per second of the fixture (time step 0.05 s).
const FPS: f64 = 20.0;

fn viewer_run(name: &str) -> (FakeRun, tempfile::TempDir) {
    let spec = FakeRun {
        static_noise: true,
        time_step: Some(1.0 / FPS),
        motion: true,
        ..FakeRun::default()
    };
    let dir = fake_run_with(name, &spec);
    report::rebuild(dir.path(), &[]).unwrap();
    (spec, dir)
}

/// Performs the interactions and writes what it saw into <pre id="viewer-test">.
const INTERACT: &str = r#"<script>
window.addEventListener('load', async () => {
  const out = {};
  try {
    const V = window.flickerViewer, $ = id => document.getElementById(id);
    const pixels = i => Array.from(V.canvas(i).getContext('2d').getImageData(0, 0, V.canvas(i).width, V.canvas(i).height).data);
    const same = (a, b) => a.length === b.length && a.every((v, k) => v === b[k]);
    const input = (el, v) => { el.value = v; el.dispatchEvent(new Event('input', { bubbles: true })); };
    const sleep = ms => new Promise(r => setTimeout(r, ms));
    await V.whenShown();
    out.labels = V.labels;
    out.first = { shown: V.state.shown, slider: +$('frame-slider').value, label: $('frame-label').textContent,
      empty: document.querySelectorAll('#panels .view.empty').length };
    const at10 = (input($('frame-slider'), 10), await V.whenShown(), pixels(1));
    input($('frame-slider'), 25);
    await V.whenShown();
    out.slider = { shown: V.state.shown, label: $('frame-label').textContent, changed: !same(at10, pixels(1)) };

    // Play at the scenario's rate, then pause.
    const from = V.state.shown;
    $('play').click();
    out.playingText = $('play').textContent;
    await sleep(500);
    $('play').click();
    await V.whenShown();
    out.play = { from, to: V.state.shown, playing: V.state.playing, fps: JSON.parse($('flicker-config').textContent).fps };

    // Exposure: the displayed bytes change, the radiance does not.
    input($('frame-slider'), 25);
    await V.whenShown();
    const k = 4 * (12 * V.canvas(1).width + 6);
    const before = pixels(1).slice(k, k + 3), valueBefore = V.valueAt(1, 6, 12);
    input($('exposure'), 2);
    out.exposure = { before, after: pixels(1).slice(k, k + 3), valueBefore, valueAfter: V.valueAt(1, 6, 12), label: $('exposure-label').textContent };
    input($('exposure'), 0);

    // Zoom with the wheel at a point: that point keeps its pixel, every panel follows.
    const r = V.view(1).getBoundingClientRect();
    const [cx, cy] = [r.left + 0.3 * r.width, r.top + 0.6 * r.height];
    const pBefore = V.pixelAt(1, cx, cy), zoomBefore = V.state.zoom;
    V.view(1).dispatchEvent(new WheelEvent('wheel', { clientX: cx, clientY: cy, deltaY: -500, bubbles: true, cancelable: true }));
    out.zoom = {
      before: pBefore, after: V.pixelAt(1, cx, cy), zoomBefore, zoomAfter: V.state.zoom,
      transforms: V.labels.map((_, i) => V.canvas(i).style.transform),
      rendering: getComputedStyle(V.canvas(1)).imageRendering,
    };
    // Pointer readout: every panel's value at the pixel under the pointer.
    V.view(1).dispatchEvent(new PointerEvent('pointermove', { clientX: cx, clientY: cy, bubbles: true }));
    out.readout = { frame: V.state.shown, pixel: V.state.pointer, text: $('pixel-label').textContent,
      values: Array.from(document.querySelectorAll('#panels .value')).map(v => v.textContent) };

    // Maps: FLIP where a reference exists, SMAPE against the previous frame.
    document.querySelector('[data-mode=flip]').click();
    input($('frame-slider'), 20);
    await V.whenShown();
    out.flip20 = { value: V.valueAt(1, 6, 12), empty: V.view(1).classList.contains('empty') };
    input($('frame-slider'), 21);
    await V.whenShown();
    out.flip21 = { value: V.valueAt(1, 6, 12), empty: V.view(1).classList.contains('empty') };
    document.querySelector('[data-mode=smape]').click();
    await V.whenShown();
    out.smape21 = { value: V.valueAt(1, 40, 12), empty: V.view(1).classList.contains('empty') };
    document.querySelector('[data-mode=motion]').click();
    await V.whenShown();
    out.motion21 = { value: V.valueAt(1, 6, 12), empty: V.view(1).classList.contains('empty'), otherEmpty: V.view(2).classList.contains('empty'),
      pixel: pixels(1).slice(4 * (12 * V.canvas(1).width + 6), 4 * (12 * V.canvas(1).width + 6) + 3) };
    // The JOD map (ColorVideoVDP) where a reference exists.
    document.querySelector('[data-mode=jod]').click();
    input($('frame-slider'), 20);
    await V.whenShown();
    out.jod20 = { value: V.valueAt(1, 6, 12), empty: V.view(1).classList.contains('empty') };
    document.querySelector('[data-mode=image]').click();

    // Events on the slider; chart cursors follow the frame.
    out.marks = Array.from(document.querySelectorAll('.event-mark')).map(m => ({ frame: +m.dataset.frame, left: parseFloat(m.style.left), title: m.title }));
    const cursor = () => { const c = document.querySelector('.chart[data-f1]'); return { left: parseFloat(c.querySelector('.cursor').style.left), ...c.dataset }; };
    input($('frame-slider'), 0);
    out.cursor0 = cursor();
    input($('frame-slider'), 15);
    out.cursor15 = cursor();
    await V.whenShown();
    out.views = V.labels.map((_, i) => { const b = V.view(i).getBoundingClientRect(); return [b.left, b.top, b.width, b.height]; });
  } catch (e) {
    out.error = String((e && e.stack) || e);
  }
  out.errors = window.__errors;
  const d = document.createElement('pre');
  d.id = 'viewer-test';
  d.textContent = JSON.stringify(out);
  document.body.appendChild(d);
});
</script>"#;

fn interact(bin: &Path, run: &Path) -> Value {
    let html = std::fs::read_to_string(run.join("report.html")).unwrap();
    let page = run.join("interact.html");
    std::fs::write(
        &page,
        html.replacen("<head>", &format!("<head>{ERROR_HOOK}"), 1).replacen(
            "</body>",
            &format!("{INTERACT}</body>"),
            1,
        ),
    )
    .unwrap();
    let out = browser(bin, run, &["--dump-dom".into()], &file_url(&page));
    let dom = String::from_utf8_lossy(&out.stdout);
    let text = element_text(&dom, "viewer-test").unwrap_or_else(|| {
        panic!(
            "the interaction script did not finish; stderr:\n{}",
            String::from_utf8_lossy(&out.stderr)
        )
    });
    serde_json::from_str(&text).unwrap()
}

fn f(v: &Value) -> f64 {
    v.as_f64().unwrap_or_else(|| panic!("{v} is not a number"))
}

#[test]
fn slider_play_exposure_zoom_maps_and_pixel_values() {
    let bin = chromium();
    let (spec, tmp) = viewer_run("interact");
    let run = tmp.path().to_path_buf();
    let out = interact(&bin, &run);
    assert!(out.get("error").is_none(), "script error: {}", out["error"]);
    assert_eq!(out["errors"], serde_json::json!([]), "console errors");
    assert_eq!(out["labels"], serde_json::json!(["reference", "pt_1spp", "cache_ema"]));
    // The page opens on the event's frame (it has a reference), every panel drawn.
    assert_eq!(
        out["first"],
        serde_json::json!({"shown": EVENT, "slider": EVENT, "label": format!("frame {EVENT} / {}", spec.frames - 1), "empty": 0}),
        "the viewer does not open on the event"
    );

    // The slider changes the frame shown.
    assert_eq!(out["slider"]["shown"], 25);
    assert_eq!(out["slider"]["label"], "frame 25 / 29");
    assert_eq!(
        out["slider"]["changed"], true,
        "frame 25 looks like frame 10, though the light changed at 20"
    );

    // Play advances frames, no faster than the scenario's rate (500 ms at 20 frames/s = 10).
    assert_eq!(out["playingText"], "pause");
    assert_eq!(f(&out["play"]["fps"]), FPS);
    let (from, to) = (out["play"]["from"].as_u64().unwrap(), out["play"]["to"].as_u64().unwrap());
    let advanced = (to + spec.frames as u64 - from) % spec.frames as u64;
    assert!((2..=11).contains(&advanced), "played from {from} to {to}");
    assert_eq!(out["play"]["playing"], false, "pause stops playback");

    // Exposure +2 EV: displayed bytes brighten, radiance under them is unchanged.
    let (before, after) = (&out["exposure"]["before"], &out["exposure"]["after"]);
    for c in 0..3 {
        assert!(
            f(&after[c]) > f(&before[c]) + 20.0,
            "exposure did not brighten: {before} -> {after}"
        );
    }
    assert_eq!(out["exposure"]["valueBefore"], out["exposure"]["valueAfter"]);
    assert_eq!(out["exposure"]["label"], "+2 EV");

    // Zoom keeps the pixel under the cursor, in every panel, with square pixels.
    let z = &out["zoom"];
    assert_eq!(z["before"], z["after"], "the pixel under the cursor moved while zooming");
    assert!(f(&z["zoomAfter"]) > 1.5 * f(&z["zoomBefore"]));
    let t = z["transforms"].as_array().unwrap();
    assert!(
        t.iter().all(|x| x == &t[0]) && t[0].as_str().unwrap().contains("scale"),
        "panels not synchronised: {t:?}"
    );
    assert_eq!(z["rendering"], "pixelated");

    // The values under the pointer are each method's radiance at that pixel (RGBE: ~1%).
    let (x, y) = (
        out["readout"]["pixel"][0].as_u64().unwrap() as u32,
        out["readout"]["pixel"][1].as_u64().unwrap() as u32,
    );
    assert_eq!(out["readout"]["text"], format!("pixel ({x}, {y})"));
    let frame = out["readout"]["frame"].as_u64().unwrap() as u32;
    let values = out["readout"]["values"].as_array().unwrap();
    assert_eq!(values[0], "", "no reference at frame {frame}");
    for (m, method) in spec.methods.iter().enumerate() {
        let exr =
            load_image(run.join(format!("frames/{method}/{frame:04}.exr"))).unwrap().get(x, y);
        let shown: Vec<f32> = values[m + 1]
            .as_str()
            .unwrap()
            .split_whitespace()
            .map(|v| v.parse().unwrap())
            .collect();
        assert_eq!(shown.len(), 3, "{method}: {shown:?}");
        let max = exr.iter().cloned().fold(0.0, f32::max);
        for c in 0..3 {
            assert!(
                (shown[c] - exr[c]).abs() <= max / 100.0,
                "{method} at ({x}, {y}): page {shown:?}, EXR {exr:?}"
            );
        }
    }

    // FLIP map at a reference frame is the run's FLIP map; none between references.
    let reference = load_image(run.join("reference/0020.exr")).unwrap();
    let img20 = load_image(run.join("frames/pt_1spp/0020.exr")).unwrap();
    let flip = flip_hdr(&reference, &img20, DEFAULT_PPD).map[(12 * spec.width + 6) as usize];
    assert_eq!(out["flip20"]["empty"], false);
    assert!(
        (f(&out["flip20"]["value"][0]) - flip as f64).abs() <= 1.0 / 255.0 + 1e-6,
        "FLIP {} vs {flip}",
        out["flip20"]["value"]
    );
    // The JOD map as the report wrote it (frames/METHOD/jod/), quantized to 1/255 in the page.
    let jod = load_image(run.join("frames/pt_1spp/jod/0020.exr")).unwrap().get(6, 12)[0];
    assert_eq!(out["jod20"]["empty"], false);
    assert!(
        (f(&out["jod20"]["value"][0]) - jod.clamp(0.0, 1.0) as f64).abs() <= 1.0 / 255.0 + 1e-6,
        "JOD map {} vs {jod}",
        out["jod20"]["value"]
    );
    assert_eq!(out["flip21"]["empty"], true);
    assert!(out["flip21"]["value"].is_null());
    // SMAPE at frame 21 against frame 20 (the right half changes while cache_ema adapts).
    let img21 = load_image(run.join("frames/pt_1spp/0021.exr")).unwrap();
    let s = smape(&img21, &img20, 0.01).map[(12 * spec.width + 40) as usize] as f64;
    assert_eq!(out["smape21"]["empty"], false);
    assert!(
        (f(&out["smape21"]["value"][0]) - s).abs() < 0.02,
        "SMAPE {} vs {s}",
        out["smape21"]["value"]
    );

    // Motion vectors of the method that records them, as written (1/8 pixel steps), coloured.
    let [dx, dy] = motion(6, 12, 21);
    assert_eq!(out["motion21"]["empty"], false);
    assert!(
        (f(&out["motion21"]["value"][0]) - dx as f64).abs() <= 1.0 / 16.0
            && (f(&out["motion21"]["value"][1]) - dy as f64).abs() <= 1.0 / 16.0,
        "{}",
        out["motion21"]
    );
    assert!(
        out["motion21"]["pixel"].as_array().unwrap().iter().any(|c| f(c) > 20.0),
        "motion drawn black: {}",
        out["motion21"]
    );
    assert_eq!(out["motion21"]["otherEmpty"], true, "cache_ema records no motion");

    // The event is marked on the slider at its frame.
    let marks = out["marks"].as_array().unwrap();
    assert_eq!(marks.len(), 1);
    assert_eq!(marks[0]["frame"], EVENT);
    assert!((f(&marks[0]["left"]) - 100.0 * EVENT as f64 / (spec.frames - 1) as f64).abs() < 0.01);
    assert!(marks[0]["title"].as_str().unwrap().contains("rotate light"));

    // Chart cursors sit at the frame, along the chart's own frame axis.
    let (c0, c15) = (&out["cursor0"], &out["cursor15"]);
    let num = |c: &Value, k: &str| c[k].as_str().unwrap().parse::<f64>().unwrap();
    let at = |c: &Value, frame: f64| {
        100.0
            * (num(c, "x0")
                + (frame - num(c, "f0")) / (num(c, "f1") - num(c, "f0"))
                    * (num(c, "x1") - num(c, "x0")))
            / num(c, "w")
    };
    assert!(
        (f(&c0["left"]) - at(c0, 0.0)).abs() < 0.01
            && (f(&c15["left"]) - at(c15, 15.0)).abs() < 0.01,
        "{c0} {c15}"
    );
    assert!(f(&c15["left"]) > f(&c0["left"]) + 10.0);
}

/// The opening frame: the first recorded frame at or after the first event, else frame 0.
#[test]
fn the_viewer_opens_on_the_first_event_where_a_frame_was_recorded() {
    use report::run::Event;
    use report::viewer::opening_frame;
    let at = |frames: &[u32]| -> Vec<Event> {
        frames.iter().map(|&frame| Event { frame, label: String::new() }).collect()
    };
    let all = vec![true; 30];
    assert_eq!(opening_frame(&[], &all), 0, "no event: the first frame");
    assert_eq!(opening_frame(&at(&[20, 8]), &all), 8, "the earliest event, not the first listed");
    assert_eq!(opening_frame(&at(&[0]), &all), 0);
    let mut gaps = all.clone();
    gaps[8..11].fill(false);
    assert_eq!(opening_frame(&at(&[8]), &gaps), 11, "the first frame on disk from the event on");
    assert_eq!(opening_frame(&at(&[8]), &all[..8]), 0, "stopped before the event: frame 0");
}

/// Mean absolute difference of two screenshots inside a rectangle (x, y, w, h).
fn diff(a: &image::RgbImage, b: &image::RgbImage, r: [f64; 4]) -> f64 {
    let (x0, y0) = (r[0].ceil() as u32, r[1].ceil() as u32);
    let (x1, y1) = ((r[0] + r[2]).floor() as u32, (r[1] + r[3]).floor() as u32);
    let mut sum = 0u64;
    for y in y0..y1 {
        for x in x0..x1 {
            sum += a
                .get_pixel(x, y)
                .0
                .iter()
                .zip(b.get_pixel(x, y).0)
                .map(|(p, q)| p.abs_diff(q) as u64)
                .sum::<u64>();
        }
    }
    sum as f64 / ((x1 - x0) * (y1 - y0)) as f64
}

#[test]
fn screenshots_differ_where_the_scene_changes_and_only_there() {
    let bin = chromium();
    let (_, tmp) = viewer_run("screens");
    let run = tmp.path().to_path_buf();
    // Panel positions, from the page itself in a window of the same size.
    let views = interact(&bin, &run)["views"].clone();
    let shot = |frame: u32| {
        let path = run.join(format!("shot_{frame}.png"));
        let out = browser(
            &bin,
            &run,
            &[format!("--screenshot={}", path.display())],
            &format!("{}#frame={frame}", file_url(&run.join("report.html"))),
        );
        assert!(path.exists(), "no screenshot: {}", String::from_utf8_lossy(&out.stderr));
        let img = image::open(&path).unwrap().to_rgb8();
        assert_eq!((img.width(), img.height()), WINDOW);
        img
    };
    let (a, b, c) = (shot(5), shot(10), shot(25));
    for (i, v) in views.as_array().unwrap().iter().enumerate().skip(1) {
        let r: Vec<f64> = v.as_array().unwrap().iter().map(f).collect();
        let left = [r[0], r[1], r[2] / 2.0 - 2.0, r[3]];
        let right = [r[0] + r[2] / 2.0 + 2.0, r[1], r[2] / 2.0 - 2.0, r[3]];
        // Before the event nothing moves: frames 5 and 10 look the same.
        assert_eq!(
            diff(&a, &b, [r[0], r[1], r[2], r[3]]),
            0.0,
            "panel {i}: frames 5 and 10 differ"
        );
        // After it, the lit right half changes and the left half does not.
        assert_eq!(diff(&b, &c, left), 0.0, "panel {i}: the unlit half changed");
        assert!(
            diff(&b, &c, right) > 10.0,
            "panel {i}: the lit half did not change ({})",
            diff(&b, &c, right)
        );
    }
}

/// A page that says when the viewer first showed a frame (the load event alone comes earlier).
const FIRST_FRAME: &str = r#"<script>
window.addEventListener('load', async () => {
  await window.flickerViewer.whenShown();
  // The frames' scripts go before the dump: printing tens of MB of DOM would be timed too.
  document.querySelectorAll('script').forEach(s => s.remove());
  const d = document.createElement('pre');
  d.id = 'first-frame';
  d.textContent = 'shown ' + window.flickerViewer.state.shown + ' empty ' + document.querySelectorAll('#panels .view.empty').length + ' errors ' + window.__errors.length;
  document.body.appendChild(d);
});
</script>"#;

/// Wall time of headless Chromium from start to the dump of `page` (file path).
fn open_seconds(bin: &Path, work: &Path, page: &Path) -> (f64, String) {
    let t = std::time::Instant::now();
    let out = browser(bin, work, &["--dump-dom".into()], &file_url(page));
    (t.elapsed().as_secs_f64(), String::from_utf8_lossy(&out.stdout).into_owned())
}

/// The size the viewer must handle: 320x180, 60 frames, 6 methods. It opens with its first frame
/// (the event's) shown in every panel, from linked frames; the opening time (browser start to the first frame
/// on screen, less the browser's start on an empty page) is printed, not asserted: speed
/// belongs in benchmarks.
#[test]
fn a_320x180_60_frame_6_method_report_shows_its_first_frame() {
    let bin = chromium();
    let spec = FakeRun {
        width: 320,
        height: 180,
        frames: 60,
        event: 30,
        methods: (0..6).map(|m| format!("method_{m}")).collect(),
        reference_frames: vec![0, 30, 59],
        static_noise: false,
        time_step: Some(1.0 / 30.0),
        motion: false,
        ..FakeRun::default()
    };
    let tmp = fake_run_with("large", &spec);
    let run = tmp.path().to_path_buf();
    let t = std::time::Instant::now();
    report::rebuild(&run, &[]).unwrap();
    let build_s = t.elapsed().as_secs_f64();
    let html = std::fs::read_to_string(run.join("report.html")).unwrap();
    let page = run.join("timed.html");
    std::fs::write(
        &page,
        html.replacen("<head>", &format!("<head>{ERROR_HOOK}"), 1).replacen(
            "</body>",
            &format!("{FIRST_FRAME}</body>"),
            1,
        ),
    )
    .unwrap();
    let blank = run.join("blank.html");
    std::fs::write(
        &blank,
        "<!DOCTYPE html><html><body><pre id=\"first-frame\">blank</pre></body></html>",
    )
    .unwrap();
    let size = |p: &Path| std::fs::metadata(p).map(|m| m.len()).unwrap_or(0);
    let linked: u64 = std::fs::read_dir(run.join("viewer"))
        .map(|d| d.map(|e| size(&e.unwrap().path())).sum())
        .unwrap_or(0);
    // Best of three of each: the machine may be busy with other work.
    let mut times = Vec::new();
    for _ in 0..3 {
        let (blank_s, _) = open_seconds(&bin, &run, &blank);
        let (page_s, dom) = open_seconds(&bin, &run, &page);
        assert_eq!(
            element_text(&dom, "first-frame").as_deref(),
            Some(format!("shown {} empty 0 errors 0", spec.event).as_str()),
            "the event's frame was not shown in every panel"
        );
        times.push((page_s - blank_s, page_s, blank_s));
    }
    let (open, page_s, blank_s) = times.into_iter().min_by(|a, b| a.0.total_cmp(&b.0)).unwrap();
    let mb = |b: u64| b as f64 / (1u64 << 20) as f64;
    eprintln!(
        "320x180, 60 frames, 6 methods: report.html {:.1} MB, linked frames {:.1} MB ({}), report built in {build_s:.1} s; \
         opened (first frame shown) in {open:.2} s = {page_s:.2} s less {blank_s:.2} s for an empty page",
        mb(size(&run.join("report.html"))),
        mb(linked),
        if linked > 0 { "linked" } else { "embedded" },
    );
    // This run is past the embedding threshold: its frames came from RUN/viewer/.
    assert!(
        linked > report::viewer::EMBED_LIMIT_BYTES as u64
            && size(&run.join("report.html")) < 2 << 20
    );
}

#[test]
fn compare_puts_two_runs_in_one_viewer_with_a_table_of_differences() {
    let bin = chromium();
    let a_tmp = fake_run_with("compare-a", &FakeRun::default());
    let a = a_tmp.path().to_path_buf();
    // B: the same scene with noise that holds still from frame to frame (less flicker).
    let b_tmp = fake_run_with("compare-b", &FakeRun { static_noise: true, ..FakeRun::default() });
    let b = b_tmp.path().to_path_buf();
    let args = report::ReportOptions {
        run_dir: None,
        compare: Some(vec![a.clone(), b.clone()]),
        out: None,
        charts: vec![],
    };
    let page = report::report(&args).unwrap();
    assert_eq!(page, b.join("compare.html"));
    let html = std::fs::read_to_string(&page).unwrap();
    let labels: Vec<&str> =
        html.split("data-label=\"").skip(1).map(|s| s.split('"').next().unwrap()).collect();
    assert_eq!(labels, ["reference", "A: pt_1spp", "B: pt_1spp", "A: cache_ema", "B: cache_ema"]);
    assert_eq!(html.matches("<script>flickerFrame(").count(), FRAMES as usize);
    assert_eq!(
        html.matches("\"flip:B: cache_ema\"").count(),
        2,
        "FLIP maps of B at both reference frames"
    );

    // Differences: the overall SMAPE of each run, from its frames.csv; B flickers less.
    let frames = |dir: &Path| metrics::frames_csv::Frames::load(dir).unwrap();
    let mean_smape = |dir: &Path, method: &str| {
        let f = frames(dir);
        let v: Vec<f64> =
            f.series(method, f.column("smape").unwrap()).into_iter().map(|p| p.1).collect();
        v.iter().sum::<f64>() / v.len() as f64
    };
    let row = |method: &str, column: &str| -> Vec<String> {
        let start = format!("<tr><td class=\"m\">{method}</td><td class=\"m\">{column}</td>");
        let r = html
            .split(&start)
            .nth(1)
            .unwrap_or_else(|| panic!("no row {method} {column}"))
            .split("</tr>")
            .next()
            .unwrap();
        r.split("<td").skip(1).map(|c| c.to_string()).collect()
    };
    for method in METHODS {
        let (sa, sb) = (mean_smape(&a, method), mean_smape(&b, method));
        let cells = row(method, "SMAPE");
        let num = |c: &str| {
            c.split('>').nth(1).unwrap().split('<').next().unwrap().parse::<f64>().unwrap()
        };
        assert!(
            (num(&cells[0]) - sa).abs() < 1e-4 && (num(&cells[1]) - sb).abs() < 1e-4,
            "{method}: {cells:?} vs {sa} {sb}"
        );
        assert!(sb < sa && cells[2].starts_with(" class=\"better\""), "{method}: {cells:?}");
        // GPU time is the same in both runs: no colour.
        assert!(row(method, "GPU ms")[2].starts_with(">+0.0000"));
    }

    // In the browser: every panel shows the event's frame (A's events).
    let timed = b.join("compare-check.html");
    std::fs::write(
        &timed,
        html.replacen("<head>", &format!("<head>{ERROR_HOOK}"), 1).replacen(
            "</body>",
            &format!("{FIRST_FRAME}</body>"),
            1,
        ),
    )
    .unwrap();
    let (_, dom) = open_seconds(&bin, &b, &timed);
    assert_eq!(
        element_text(&dom, "first-frame").as_deref(),
        Some(format!("shown {EVENT} empty 0 errors 0").as_str())
    );
}
