//! The walk-through (docs/walkthrough.md) runs as written. tests/docs_commands.rs runs only
//! flicker's own commands, one line at a time; the walk-through needs shell loops and Python, so
//! its blocks are marked `sh untested` there and played here instead: in document order, each
//! by `bash -euo pipefail` in a scratch folder that holds the checkout's `scenarios/` and
//! `scripts/`, with the test's own `flicker` first on PATH; a ```ron block whose first line is
//! `// PATH` is saved as PATH first, as the page tells its reader to. A command that fails fails
//! the test naming the block's line: `flicker suite run` exits 1 when a gate fails, so the
//! suite's gates (the method better than its noisy input over three seeds) are asserted too.
//! Then the outputs the page describes are checked.

use std::path::{Path, PathBuf};
use std::process::Command;
use std::time::Instant;

use pulldown_cmark::{CodeBlockKind, Event, Parser, Tag, TagEnd};

const PAGE: &str = "docs/walkthrough.md";

fn root() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
}

/// One step of the page: a shell block to run, or a file to save.
enum Step {
    Run { line: usize, script: String },
    Save { path: String, text: String },
}

fn steps(text: &str) -> Vec<Step> {
    let line_of = |offset: usize| text[..offset].lines().count() + 1;
    let mut out = Vec::new();
    let mut current: Option<(String, usize, String)> = None;
    for (event, range) in Parser::new(text).into_offset_iter() {
        match event {
            Event::Start(Tag::CodeBlock(CodeBlockKind::Fenced(info))) => {
                current = Some((info.to_string(), line_of(range.start), String::new()));
            }
            Event::Text(t) => {
                if let Some((_, _, body)) = current.as_mut() {
                    body.push_str(&t);
                }
            }
            Event::End(TagEnd::CodeBlock) => {
                let Some((info, line, body)) = current.take() else { continue };
                match info.split_whitespace().collect::<Vec<_>>().as_slice() {
                    ["sh", ..] => out.push(Step::Run { line, script: body }),
                    ["ron"] => {
                        if let Some(path) = body.lines().next().and_then(|l| l.strip_prefix("// "))
                        {
                            out.push(Step::Save { path: path.trim().to_string(), text: body });
                        }
                    }
                    _ => {}
                }
            }
            _ => {}
        }
    }
    out
}

#[cfg(unix)]
fn link(from: &Path, to: &Path) {
    std::os::unix::fs::symlink(from, to).unwrap();
}

#[test]
fn the_walkthrough_runs_as_written() {
    let text = std::fs::read_to_string(root().join(PAGE)).unwrap();
    let steps = steps(&text);
    let runs = steps.iter().filter(|s| matches!(s, Step::Run { .. })).count();
    assert!(
        runs >= 5,
        "{PAGE}: {runs} shell blocks; expected export, method, measure, report, suite"
    );
    assert!(steps.iter().any(|s| matches!(s, Step::Save { .. })), "{PAGE}: no suite file to save");

    let target_tmp = PathBuf::from(env!("CARGO_TARGET_TMPDIR"));
    let tmp = tempfile::Builder::new().prefix("walkthrough_").tempdir_in(&target_tmp).unwrap();
    let dir = tmp.path().to_path_buf();
    std::fs::create_dir_all(dir.join("bin")).unwrap();
    for shared in ["scenarios", "scripts"] {
        link(&root().join(shared), &dir.join(shared));
    }
    link(Path::new(env!("CARGO_BIN_EXE_flicker")), &dir.join("bin/flicker"));
    // The page's `python3` is the tests' interpreter (the checkout's .venv where it exists).
    let path = format!(
        "{}:{}",
        dir.join("bin").display(),
        metrics::python::path_with_interpreter().to_string_lossy()
    );

    for step in &steps {
        match step {
            Step::Save { path, text } => {
                let file = dir.join(path);
                std::fs::create_dir_all(file.parent().unwrap()).unwrap();
                std::fs::write(file, text).unwrap();
            }
            Step::Run { line, script } => {
                let start = Instant::now();
                let out = Command::new("bash")
                    .args(["-euo", "pipefail", "-c", script])
                    .current_dir(&dir)
                    .env("PATH", &path)
                    .env("FLICKER_CACHE_DIR", target_tmp.join("walkthrough_cache"))
                    .output()
                    .expect("bash runs");
                let stdout = String::from_utf8_lossy(&out.stdout);
                let stderr = String::from_utf8_lossy(&out.stderr);
                eprintln!("{PAGE}:{line}: {:.1} s\n{stdout}", start.elapsed().as_secs_f64());
                let tail: Vec<&str> = stderr.lines().rev().take(15).collect();
                let tail: Vec<&str> = tail.into_iter().rev().collect();
                assert!(
                    out.status.success(),
                    "{PAGE}:{line}: exited with {}:\n{stdout}\n{}",
                    out.status,
                    tail.join("\n")
                );
            }
        }
    }

    // What the page says the steps wrote: the method's times in frames.csv, the report, and
    // every gate of the suite judged and passed.
    let run = dir.join("walkthrough/measured");
    assert!(run.join("report.html").is_file());
    let csv = std::fs::read_to_string(run.join("frames.csv")).unwrap();
    let header: Vec<&str> = csv.lines().next().unwrap().split(',').collect();
    for column in ["wall_ms_total", "wall_ms_reproject", "wall_ms_blend", "wall_ms_other"] {
        assert!(header.contains(&column), "no {column} in frames.csv: {header:?}");
    }
    let summary = std::fs::read_to_string(dir.join("walkthrough/suite_run/summary.md")).unwrap();
    eprintln!("{summary}");
    assert!(summary.starts_with("# Suite suite: passed"), "{summary}");
    assert_eq!(summary.matches("| pass |").count(), 3, "{summary}");
}
