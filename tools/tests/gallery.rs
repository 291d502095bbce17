//! `flicker gallery failures` on one case at a tiny size: the page it writes shows the run's own
//! frames, summary.json's numbers and the command that plays the run again, and keeps the prose
//! around its generated part.

use std::path::{Path, PathBuf};

use serde_json::Value;
use tools::gallery::{self, GalleryOptions};

const CASE: &str = "termination_glossy";
const FAILING: &str = "vb_rel_1";
const BASELINE: &str = "pt";
const COLUMNS: [&str; 3] = ["flip", "smape", "path_length"];

fn root() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).parent().unwrap().to_path_buf()
}

fn rgb(path: &Path) -> image::RgbImage {
    image::open(path).unwrap_or_else(|e| panic!("{}: {e}", path.display())).to_rgb8()
}

#[test]
fn failure_page_shows_the_runs_frames_numbers_and_command() {
    let dir = PathBuf::from(env!("CARGO_TARGET_TMPDIR"))
        .join(format!("gallery_failures_{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    let page = dir.join("failure-cases.md");
    // Prose around the generated part stays as written.
    std::fs::write(
        &page,
        "# Failure cases\n\nProse before.\n\n<!-- generated: flicker gallery failures -->\nold\n<!-- end generated -->\n\nProse after.\n",
    )
    .unwrap();
    let runs = dir.join("runs");
    let opts = GalleryOptions {
        page: page.clone(),
        images: None,
        runs: runs.clone(),
        root: root(),
        only: Some(CASE.into()),
        resolution: Some((32, 18)),
        frames: Some(2),
        cache_dir: Some(dir.join("cache")),
        progress: false,
    };
    gallery::failures(&opts).expect("the gallery plays its case");
    let text = std::fs::read_to_string(&page).unwrap();
    assert!(text.starts_with("# Failure cases\n\nProse before.\n\n<!-- generated:"), "{text}");
    assert!(text.ends_with("<!-- end generated -->\n\nProse after.\n"), "{text}");
    assert!(!text.contains("\nold\n"), "{text}");

    // The picture: the failing method's frame, the baseline's and the reference, at the run's
    // size, pixel for pixel.
    let run = runs.join(CASE);
    assert!(text.contains(&format!("](images/failures/{CASE}.png)")), "{text}");
    let picture = rgb(&dir.join("images/failures").join(format!("{CASE}.png")));
    assert_eq!(picture.dimensions(), (3 * 32 + 2 * 2, 18));
    let panels = [
        run.join("frames").join(FAILING).join("0000.png"),
        run.join("frames").join(BASELINE).join("0000.png"),
        run.join("reference/0000.png"),
    ];
    for (k, panel) in panels.iter().enumerate() {
        let panel = rgb(panel);
        let x0 = k as u32 * (32 + 2);
        for (x, y, p) in panel.enumerate_pixels() {
            assert_eq!(picture.get_pixel(x0 + x, y), p, "panel {k} at ({x}, {y})");
        }
    }

    // Every window's row of both methods, with summary.json's numbers.
    let summary: Value =
        serde_json::from_str(&std::fs::read_to_string(run.join("summary.json")).unwrap()).unwrap();
    let windows = summary["windows"].as_array().unwrap();
    assert!(!windows.is_empty());
    let mut numbers = 0;
    for w in windows {
        let name = w["name"].as_str().unwrap();
        let label = match w["event"].as_str() {
            Some(e) => format!("{name} ({e})"),
            None => name.to_string(),
        };
        for method in [FAILING, BASELINE] {
            let m = summary["methods"]
                .as_array()
                .unwrap()
                .iter()
                .find(|m| m["method"] == method)
                .unwrap_or_else(|| panic!("{method} in summary.json"));
            let cells: Vec<String> = COLUMNS
                .iter()
                .map(|c| &m["means"][name][*c])
                .chain([&m["jod"][name]])
                .map(|v| {
                    v.as_f64().map_or("—".into(), |v| {
                        numbers += 1;
                        gallery::number(v)
                    })
                })
                .collect();
            let row = format!(
                "| {label} | {}–{} | `{method}` | {} |",
                w["first"],
                w["last"],
                cells.join(" | ")
            );
            assert!(text.contains(&row), "no row\n{row}\nin\n{text}");
        }
    }
    // FLIP, SMAPE and path length at least, of both methods.
    assert!(numbers >= 6, "{numbers} numbers");

    // The pictured frame's row: frames.csv's values of that frame.
    let csv = std::fs::read_to_string(run.join("frames.csv")).unwrap();
    let header: Vec<&str> = csv.lines().next().unwrap().split(',').collect();
    for method in [FAILING, BASELINE] {
        let row: Vec<&str> = csv
            .lines()
            .map(|l| l.split(',').collect::<Vec<_>>())
            .find(|r| r[0] == method && r[1] == "0")
            .unwrap_or_else(|| panic!("{method} frame 0 in frames.csv"));
        let cells: Vec<String> = COLUMNS
            .iter()
            .map(|c| {
                // Empty where the frame has no value (SMAPE at frame 0).
                let v = row[header.iter().position(|h| h == c).unwrap()].parse::<f64>().ok();
                v.map_or("—".into(), gallery::number)
            })
            .collect();
        assert!(cells[0] != "—", "{method}: frame 0 has a reference, so a FLIP");
        let line = format!(
            "| frame 0 (pictured; frames.csv) | 0 | `{method}` | {} | — |",
            cells.join(" | ")
        );
        assert!(text.contains(&line), "no row\n{line}\nin\n{text}");
    }

    // The command that plays the run again, as a tested shell block.
    let command = format!(
        "```sh\nflicker run scenarios/termination_failure_glossy.ron --frames 2 --resolution 32x18 --out {}\n```",
        run.display()
    );
    assert!(text.contains(&command), "no\n{command}\nin\n{text}");
    assert!(text.contains("at commit "), "{text}");
    assert!(text.contains("adapter "), "{text}");
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn an_unknown_case_is_named_with_the_known_ones() {
    let dir = PathBuf::from(env!("CARGO_TARGET_TMPDIR"));
    let opts = GalleryOptions {
        page: dir.join("never.md"),
        images: None,
        runs: dir.join("never_runs"),
        root: root(),
        only: Some("no_such_case".into()),
        resolution: None,
        frames: None,
        cache_dir: None,
        progress: false,
    };
    let e = gallery::failures(&opts).unwrap_err().to_string();
    assert!(e.contains("no_such_case") && e.contains(CASE), "{e}");
}

#[test]
fn every_case_names_a_shipped_scenario_with_both_methods() {
    for case in gallery::CASES {
        let spec = playback::scenario::RunSpec::load(
            &root().join(case.scenario),
            &playback::play::Overrides::default(),
        )
        .unwrap_or_else(|e| panic!("{}: {e:#}", case.name));
        let labels: Vec<String> = spec.methods.iter().map(|m| m.label()).collect();
        for m in [case.failing, case.baseline] {
            assert!(labels.iter().any(|l| l == m), "{}: no `{m}` in {labels:?}", case.name);
        }
    }
}
