//! The commands of the documents run. Every fenced block with info string `sh` in README.md,
//! CONTRIBUTING.md, docs/** and the crate READMEs is played line by line at a small scale, with the test's own
//! `flicker` binary; a block `sh untested` is not run but listed. A failing command fails the
//! test naming its file:line and the tail of its stderr. An `sh untested` block must have a
//! paragraph right before or right after it (which says why it is not run: its own test covers
//! it, it needs a GPU or Slurm, it takes long); the test cannot judge the reason, it lists every
//! untested block instead.
//!
//! A line of an `sh` block (after `\` continuations are joined and ` # comments` dropped) is:
//! - `flicker ARGS` or `cargo run --release -- ARGS`: `flicker ARGS`, where ARGS starts with
//!   `run`, `report`, `schedule`, `scenes` or `compare` (or is a `--help`);
//! - `bash scripts/setup.sh && REST`: REST (the set-up is the machine's, not the test's).
//!
//! `flicker run` gets `--frames 2 --resolution 32x18 --out TMP/OUT --cache-dir CACHE
//! --quiet`, replacing those flags where the line has them; OUT is the line's `--out` or
//! the scenario's output (`runs/NAME`), so a later `flicker report runs/NAME` of the same
//! document finds it: an argument naming a path that an earlier command wrote under TMP is
//! read from TMP. Any other line fails: mark its block `sh untested` and say in the text why it
//! is not run here.

mod docs_common;

use std::io::Read;
use std::path::{Path, PathBuf};
use std::process::{Command, Stdio};
use std::time::{Duration, Instant};

use docs_common::{Doc, documents, root};
use pulldown_cmark::{CodeBlockKind, Event, Tag, TagEnd};

/// The flags `flicker run` gets from the test (each takes a value but the last).
const RUN_FLAGS: [&str; 4] = ["--frames", "--resolution", "--out", "--cache-dir"];
/// The subcommands the test runs.
const RUNNABLE: [&str; 5] = ["run", "report", "schedule", "scenes", "compare"];
/// The longest one command may take (a 32x18, 2-frame run takes seconds on lavapipe).
const COMMAND_LIMIT: Duration = Duration::from_secs(300);

/// One `sh` (or `sh untested`) block's commands, each with its line in the document.
struct Block {
    place: String,
    untested: bool,
    lines: Vec<(usize, String)>,
}

/// The shell blocks of `doc`; a block in another shell's name (`bash`, `console`, `shell`,
/// `zsh`) is an error: it would escape the test.
fn blocks(doc: &Doc) -> (Vec<Block>, Vec<String>) {
    let (mut out, mut errors) = (Vec::new(), Vec::new());
    let mut current: Option<(Block, usize, String)> = None;
    // Whether the last block that ended was a paragraph (the reason an untested block gives),
    // and an untested block with none before it, waiting for one right after it.
    let mut after_paragraph = false;
    let mut unexplained: Option<String> = None;
    let no_reason = |place: String| {
        format!(
            "{place}: an ```sh untested block without a paragraph right before or after it; expected the text next to it to say why it is not run"
        )
    };
    for (event, range) in doc.events() {
        match &event {
            Event::Start(Tag::Paragraph) => unexplained = None,
            Event::Start(
                Tag::Heading { .. }
                | Tag::CodeBlock(_)
                | Tag::Table(_)
                | Tag::List(_)
                | Tag::BlockQuote(_)
                | Tag::HtmlBlock,
            ) => errors.extend(unexplained.take().map(no_reason)),
            _ => {}
        }
        match event {
            Event::End(TagEnd::Paragraph) => after_paragraph = true,
            Event::End(
                TagEnd::Heading(_)
                | TagEnd::Table
                | TagEnd::List(_)
                | TagEnd::BlockQuote(_)
                | TagEnd::HtmlBlock,
            ) => after_paragraph = false,
            Event::Start(Tag::CodeBlock(CodeBlockKind::Fenced(info))) => {
                let words: Vec<&str> = info.split_whitespace().collect();
                let place = doc.place(range.start);
                if words == ["sh", "untested"] && !after_paragraph {
                    unexplained = Some(place.clone());
                }
                match words.as_slice() {
                    ["sh"] | ["sh", "untested"] => {
                        let block = Block { place, untested: words.len() == 2, lines: Vec::new() };
                        // The block's text starts on the line after the fence.
                        current = Some((block, doc.line(range.start) + 1, String::new()));
                    }
                    [first, ..] if ["sh", "bash", "shell", "console", "zsh", "shell-session"].contains(first) => {
                        errors.push(format!(
                            "{place}: a ```{info} block; expected ```sh (run by tests/docs_commands.rs) or ```sh untested (with the reason in the text)"
                        ))
                    }
                    _ => {}
                }
            }
            Event::Text(t) => {
                if let Some((_, _, text)) = current.as_mut() {
                    text.push_str(&t);
                }
            }
            Event::End(TagEnd::CodeBlock) => {
                after_paragraph = false;
                if let Some((mut block, first_line, text)) = current.take() {
                    block.lines = command_lines(&text, first_line);
                    out.push(block);
                }
            }
            _ => {}
        }
    }
    errors.extend(unexplained.take().map(no_reason));
    (out, errors)
}

/// The commands of a block's text: `\` continuations joined, comments and blank lines dropped.
fn command_lines(text: &str, first_line: usize) -> Vec<(usize, String)> {
    let mut out = Vec::new();
    let mut pending: Option<(usize, String)> = None;
    for (i, raw) in text.lines().enumerate() {
        let (start, mut acc) = pending.take().unwrap_or((first_line + i, String::new()));
        let line = strip_comment(raw);
        if let Some(head) = line.trim_end().strip_suffix('\\') {
            acc.push_str(head);
            acc.push(' ');
            pending = Some((start, acc));
            continue;
        }
        acc.push_str(&line);
        if !acc.trim().is_empty() {
            out.push((start, acc.split_whitespace().collect::<Vec<_>>().join(" ")));
        }
    }
    if let Some((start, acc)) = pending {
        out.push((start, acc.trim().to_string()));
    }
    out
}

/// A line without its ` # comment` (a `#` outside quotes that starts a word).
fn strip_comment(line: &str) -> String {
    let (mut quote, mut prev_blank) = (None, true);
    for (i, c) in line.char_indices() {
        match (quote, c) {
            (None, '\'' | '"') => quote = Some(c),
            (Some(q), c) if c == q => quote = None,
            (None, '#') if prev_blank => return line[..i].to_string(),
            _ => {}
        }
        prev_blank = c.is_whitespace();
    }
    line.to_string()
}

/// Words of a command line as sh splits them (single and double quotes, no expansions).
fn words(line: &str) -> Result<Vec<String>, String> {
    let (mut out, mut cur, mut quote, mut any) = (Vec::new(), String::new(), None, false);
    for c in line.chars() {
        match (quote, c) {
            (None, '\'' | '"') => {
                quote = Some(c);
                any = true;
            }
            (Some(q), c) if c == q => quote = None,
            (None, c) if c.is_whitespace() => {
                if any {
                    out.push(std::mem::take(&mut cur));
                    any = false;
                }
            }
            (None, '|' | '>' | '<' | ';' | '&' | '$' | '`' | '*' | '?' | '[') => {
                return Err(format!("shell syntax `{c}`"));
            }
            _ => {
                cur.push(c);
                any = true;
            }
        }
    }
    if quote.is_some() {
        return Err("an unclosed quote".into());
    }
    if any {
        out.push(cur);
    }
    Ok(out)
}

/// The `flicker` arguments of a document's line, or why the test cannot run it.
fn flicker_args(line: &str) -> Result<Option<Vec<String>>, String> {
    let line = match line.strip_prefix("bash scripts/setup.sh") {
        Some(rest) => match rest.trim().strip_prefix("&&") {
            Some(r) => r.trim(),
            None if rest.trim().is_empty() => return Ok(None),
            None => return Err("expected `bash scripts/setup.sh && COMMAND`".into()),
        },
        None => line,
    };
    let args = if let Some(rest) = line.strip_prefix("cargo run --release -- ") {
        rest
    } else if let Some(rest) = line.strip_prefix("flicker ") {
        rest
    } else {
        return Err(
            "not a command the guide test runs (`flicker ...` or `cargo run --release -- ...`)"
                .into(),
        );
    };
    let args = words(args)?;
    let runnable = args.iter().any(|a| a == "--help" || a == "-h")
        || args.first().is_some_and(|a| RUNNABLE.contains(&a.as_str()) || a == "help");
    if !runnable {
        return Err(format!(
            "`flicker {}` is not one the guide test runs ({})",
            args.first().map_or("", |a| a),
            RUNNABLE.join(", ")
        ));
    }
    Ok(Some(args))
}

/// Where one document's commands write: TMP (run folders) and CACHE (references, warm starts).
struct Sandbox {
    tmp: PathBuf,
    cache: PathBuf,
}

impl Sandbox {
    /// `arg` read from TMP where it names a file there (what an earlier command wrote).
    fn path_arg(&self, arg: &str) -> String {
        let rel = arg.trim_start_matches('/');
        if !rel.is_empty() && self.tmp.join(rel).exists() {
            return self.tmp.join(rel).display().to_string();
        }
        arg.to_string()
    }

    /// The arguments actually given to `flicker`.
    fn rewrite(&self, args: &[String]) -> Vec<String> {
        if args.first().map(String::as_str) != Some("run") || args.iter().any(|a| a == "--help") {
            return args.iter().map(|a| self.path_arg(a)).collect();
        }
        let (mut kept, mut out_dir, mut i) = (Vec::new(), None, 0);
        while i < args.len() {
            let a = &args[i];
            let (flag, inline) = match a.split_once('=') {
                Some((f, v)) => (f, Some(v.to_string())),
                None => (a.as_str(), None),
            };
            if RUN_FLAGS.contains(&flag) {
                let value = inline.or_else(|| {
                    i += 1;
                    args.get(i).cloned()
                });
                if flag == "--out" {
                    out_dir = value;
                }
            } else if a != "--quiet" {
                kept.push(a.clone());
            }
            i += 1;
        }
        let out_dir = out_dir.map(PathBuf::from).or_else(|| {
            let scenario = kept.iter().skip(1).find(|a| !a.starts_with('-'))?;
            sim::Scenario::load(&root().join(scenario)).ok().map(|s| s.output)
        });
        let out_dir = out_dir.unwrap_or_else(|| PathBuf::from("runs/unnamed"));
        let out_dir = self.tmp.join(out_dir.strip_prefix("/").unwrap_or(&out_dir));
        kept.extend(
            [
                "--frames",
                "2",
                "--resolution",
                "32x18",
                "--out",
                &out_dir.display().to_string(),
                "--cache-dir",
                &self.cache.display().to_string(),
                "--quiet",
            ]
            .map(String::from),
        );
        kept
    }
}

/// Runs `flicker args` in the repository root; Err with the exit status and stderr's tail.
fn run_flicker(args: &[String], cache: &Path) -> Result<(), String> {
    let mut child = Command::new(env!("CARGO_BIN_EXE_flicker"))
        .args(args)
        .current_dir(root())
        .env("FLICKER_CACHE_DIR", cache)
        .stdin(Stdio::null())
        .stdout(Stdio::null())
        .stderr(Stdio::piped())
        .spawn()
        .map_err(|e| format!("cannot start flicker: {e}"))?;
    let mut stderr = child.stderr.take().expect("piped stderr");
    let reader = std::thread::spawn(move || {
        let mut s = String::new();
        let _ = stderr.read_to_string(&mut s);
        s
    });
    let start = Instant::now();
    let status = loop {
        if let Some(status) = child.try_wait().map_err(|e| e.to_string())? {
            break Some(status);
        }
        if start.elapsed() > COMMAND_LIMIT {
            let _ = child.kill();
            let _ = child.wait();
            break None;
        }
        std::thread::sleep(Duration::from_millis(50));
    };
    let err = reader.join().unwrap_or_default();
    let tail: Vec<&str> =
        err.lines().rev().take(12).collect::<Vec<_>>().into_iter().rev().collect();
    match status {
        Some(s) if s.success() => Ok(()),
        Some(s) => Err(format!("exited with {s}; stderr:\n    {}", tail.join("\n    "))),
        None => Err(format!(
            "still running after {COMMAND_LIMIT:?}; stderr:\n    {}",
            tail.join("\n    ")
        )),
    }
}

/// What running every `sh` block of `docs` found: failures (`file:line: ...`), the commands run
/// and the untested blocks (`file:line: first command`).
struct Outcome {
    failures: Vec<String>,
    ran: Vec<String>,
    untested: Vec<String>,
}

fn run_documents(docs: &[Doc], scratch: &Path) -> Outcome {
    let mut o = Outcome { failures: Vec::new(), ran: Vec::new(), untested: Vec::new() };
    // References and NIRC warm starts are keyed by what they depend on: one cache for every
    // run of the test and across runs (a warm start of 160 pre-training frames costs about 20 s
    // at 32x18 on lavapipe).
    let cache = PathBuf::from(env!("CARGO_TARGET_TMPDIR")).join("docs_commands_cache");
    for (n, doc) in docs.iter().enumerate() {
        let sandbox = Sandbox { tmp: scratch.join(format!("doc{n}")), cache: cache.clone() };
        let (blocks, errors) = blocks(doc);
        o.failures.extend(errors);
        for block in blocks {
            if block.untested {
                let first = block.lines.first().map_or("", |(_, l)| l.as_str());
                o.untested.push(format!("{}: {first}", block.place));
                continue;
            }
            for (line, command) in &block.lines {
                let place = format!("{}:{line}", doc.path.display());
                match flicker_args(command) {
                    Ok(None) => {}
                    Ok(Some(args)) => {
                        let args = sandbox.rewrite(&args);
                        let start = Instant::now();
                        let result = run_flicker(&args, &cache);
                        o.ran.push(format!("{place}: flicker {} ({:.1} s)", args.join(" "), start.elapsed().as_secs_f64()));
                        if let Err(e) = result {
                            o.failures.push(format!("{place}: `{command}` {e}"));
                        }
                    }
                    Err(why) => o.failures.push(format!(
                        "{place}: `{command}`: {why}; mark the block ```sh untested and say why in the text"
                    )),
                }
            }
        }
    }
    o
}

fn scratch(name: &str) -> PathBuf {
    let dir = PathBuf::from(env!("CARGO_TARGET_TMPDIR"))
        .join(format!("docs_commands_{name}_{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).expect("scratch folder");
    dir
}

#[test]
fn the_documents_commands_run() {
    let dir = scratch("documents");
    let start = Instant::now();
    let o = run_documents(&documents(), &dir);
    eprintln!(
        "ran {} commands in {:.1} s:\n{}",
        o.ran.len(),
        start.elapsed().as_secs_f64(),
        o.ran.join("\n")
    );
    eprintln!("{} blocks `sh untested` (not run):\n{}", o.untested.len(), o.untested.join("\n"));
    assert!(
        o.failures.is_empty(),
        "{} commands fail:\n{}",
        o.failures.len(),
        o.failures.join("\n")
    );
    let _ = std::fs::remove_dir_all(&dir);
}

// The rules on their own, and the runner on small fixtures.

#[test]
fn lines_become_flicker_commands() {
    let args = |l: &str| flicker_args(l).map(|a| a.map(|a| a.join(" ")));
    assert_eq!(
        args("bash scripts/setup.sh && cargo run --release -- run scenarios/showcase.ron"),
        Ok(Some("run scenarios/showcase.ron".into()))
    );
    assert_eq!(args("bash scripts/setup.sh"), Ok(None));
    assert_eq!(args("flicker report runs/x"), Ok(Some("report runs/x".into())));
    assert_eq!(args("flicker compare 'a b.png' c.png"), Ok(Some("compare a b.png c.png".into())));
    assert!(
        args("flicker reproduce all --scale lab")
            .unwrap_err()
            .contains("is not one the guide test runs")
    );
    assert!(
        args("cargo test --workspace").unwrap_err().contains("not a command the guide test runs")
    );
    assert!(args("flicker run a.ron > log").unwrap_err().contains("shell syntax `>`"));
    let text = "flicker run a.ron \\\n    --out /tmp/x   # a comment\n\n# only a comment\nflicker scenes\n";
    assert_eq!(
        command_lines(text, 10),
        [(10, "flicker run a.ron --out /tmp/x".to_string()), (14, "flicker scenes".to_string())]
    );
}

#[test]
fn runs_get_the_small_scale_and_a_sandbox() {
    let sandbox = Sandbox { tmp: PathBuf::from("/T"), cache: PathBuf::from("/C") };
    let words = |s: &str| s.split(' ').map(String::from).collect::<Vec<_>>();
    assert_eq!(
        sandbox
            .rewrite(&words("run scenarios/cornell_box.ron --frames 100 --resolution=640x360"))
            .join(" "),
        "run scenarios/cornell_box.ron --frames 2 --resolution 32x18 --out /T/runs/cornell_box --cache-dir /C --quiet"
    );
    assert_eq!(
        sandbox.rewrite(&words("run scenarios/cornell_box.ron --out /tmp/tc --seed 3")).join(" "),
        "run scenarios/cornell_box.ron --seed 3 --frames 2 --resolution 32x18 --out /T/tmp/tc --cache-dir /C --quiet"
    );
}

/// The deliberate breaks: a failing command, a line the test does not run, a `bash` block.
/// The untested block is listed, not run; the passing command passes.
#[test]
fn a_failing_command_fails_naming_file_and_line() {
    let text = "# Fixture\n\n```sh\nflicker scenes\nflicker run scenarios/no_such_scenario.ron\n```\n\n\
                Not run here: it needs Slurm.\n\n```sh untested\nsbatch runs/x/sweep.sbatch\n```\n\n\
                ```sh\ncargo test --workspace\n```\n\n```bash\nflicker scenes\n```\n\n\
                ## Heading\n\n```sh untested\nflicker reproduce all\n```\n\n## Other\n\n\
                ```sh untested\nflicker bench\n```\n\n(Not run here: it takes minutes.)\n";
    let mut o = run_documents(&[Doc::new("fixture.md", text)], &scratch("fixture"));
    assert_eq!(o.ran.len(), 2, "{:?}", o.ran);
    assert_eq!(
        o.untested,
        [
            "fixture.md:10: sbatch runs/x/sweep.sbatch",
            "fixture.md:24: flicker reproduce all",
            "fixture.md:30: flicker bench"
        ]
    );
    assert_eq!(o.failures.len(), 4, "{:#?}", o.failures);
    assert!(o.failures[0].starts_with("fixture.md:18: a ```bash block"), "{}", o.failures[0]);
    assert!(
        o.failures[1]
            .starts_with("fixture.md:24: an ```sh untested block without a paragraph right"),
        "{}",
        o.failures[1]
    );
    o.failures.remove(1);
    assert!(
        o.failures[1]
            .starts_with("fixture.md:5: `flicker run scenarios/no_such_scenario.ron` exited with"),
        "{}",
        o.failures[1]
    );
    assert!(
        o.failures[1].contains("no_such_scenario.ron"),
        "the stderr tail names the file: {}",
        o.failures[1]
    );
    assert!(
        o.failures[2].starts_with("fixture.md:15: `cargo test --workspace`: not a command"),
        "{}",
        o.failures[2]
    );
}
