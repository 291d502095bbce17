//! Property tests of every parser of user files: random mutations of the shipped scenario,
//! suite, sweep and claims files, density grids and OBJ bounds. Whatever the text, a parser
//! returns a valid result or an error that names the file, with line and column where the
//! text gives one; it never panics. PROPTEST_CASES sets the cases per file kind (default 5000;
//! about a second each on 2 cores; 20000 passed locally).

use std::path::{Path, PathBuf};

use proptest::prelude::*;
use proptest::sample::Index;
use proptest::test_runner::{Config, TestCaseError, TestRunner};

/// A fixed seed, so that CI runs the same cases each time; PROPTEST_RNG_SEED explores others.
fn rng_seed() -> proptest::test_runner::RngSeed {
    match std::env::var("PROPTEST_RNG_SEED").ok().and_then(|v| v.parse().ok()) {
        Some(seed) => proptest::test_runner::RngSeed::Fixed(seed),
        None => proptest::test_runner::RngSeed::Fixed(0x9a_75e7),
    }
}

/// Tokens that RON, the grid and OBJ readers treat specially, and edge values.
const TOKENS: &[&str] = &[
    "NaN",
    "inf",
    "-inf",
    "1e39",
    "-1",
    "0",
    "4294967296",
    "18446744073709551616",
    "0.5",
    "(",
    ")",
    "[",
    "]",
    "{",
    "}",
    ",",
    ":",
    "\"",
    "'",
    "//",
    "/*",
    "*/",
    "Some(",
    "None",
    "true",
    "r#\"",
    "\\",
    "é",
    "\u{0}",
    " ",
    "\n",
    "#",
    "methods: []",
    "frames: 0",
    "resolution: (0, 0)",
    "PathTracing(spp: 1)",
    "name",
    "x",
    "v",
    "f 1 2 3",
    "density_grid 1 1 1",
    "cases",
];

#[derive(Clone, Debug)]
enum Mutation {
    Delete(Index, usize),
    Insert(Index, usize),
    Replace(Index, char),
    Duplicate(Index, usize),
}

fn mutation() -> impl Strategy<Value = Mutation> {
    prop_oneof![
        (any::<Index>(), 1..24usize).prop_map(|(at, n)| Mutation::Delete(at, n)),
        (any::<Index>(), 0..TOKENS.len()).prop_map(|(at, t)| Mutation::Insert(at, t)),
        (any::<Index>(), any::<char>()).prop_map(|(at, c)| Mutation::Replace(at, c)),
        (any::<Index>(), 1..40usize).prop_map(|(at, n)| Mutation::Duplicate(at, n)),
    ]
}

fn apply(text: &str, mutations: &[Mutation]) -> String {
    let mut chars: Vec<char> = text.chars().collect();
    for m in mutations {
        let at = |i: &Index, extra: usize| i.index(chars.len() + extra);
        match m {
            Mutation::Delete(i, n) if !chars.is_empty() => {
                let s = at(i, 0);
                chars.drain(s..(s + n).min(chars.len()));
            }
            Mutation::Insert(i, t) => {
                let s = at(i, 1);
                chars.splice(s..s, TOKENS[*t].chars());
            }
            Mutation::Replace(i, c) if !chars.is_empty() => {
                let s = at(i, 0);
                chars[s] = *c;
            }
            Mutation::Duplicate(i, n) if !chars.is_empty() => {
                let s = at(i, 0);
                let piece: Vec<char> = chars[s..(s + n).min(chars.len())].to_vec();
                chars.splice(s..s, piece);
            }
            _ => {}
        }
    }
    chars.into_iter().collect()
}

fn root() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("..")
}

fn shipped(folder: &str, ext: &str) -> Vec<(PathBuf, String)> {
    let mut files: Vec<PathBuf> = std::fs::read_dir(root().join(folder))
        .unwrap()
        .map(|e| e.unwrap().path())
        .filter(|p| p.extension().is_some_and(|e| e == ext))
        .collect();
    files.sort();
    assert!(!files.is_empty(), "no {folder}/*.{ext}");
    files.into_iter().map(|p| (p.clone(), std::fs::read_to_string(&p).unwrap())).collect()
}

fn cases() -> u32 {
    std::env::var("PROPTEST_CASES").ok().and_then(|v| v.parse().ok()).unwrap_or(5000)
}

/// Mutates the files `cases()` times and checks `parse` on each text. `parse` returns the
/// error's text, `Ok` when the mutated file is still valid.
fn fuzz(files: &[(PathBuf, String)], parse: impl Fn(&str, &Path) -> Result<(), String>) {
    let config = Config {
        cases: cases(),
        failure_persistence: None,
        rng_seed: rng_seed(),
        ..Config::default()
    };
    let strategy = (0..files.len(), prop::collection::vec(mutation(), 1..6));
    let (valid, errors) = (std::cell::Cell::new(0u32), std::cell::Cell::new(0u32));
    TestRunner::new(config)
        .run(&strategy, |(f, mutations)| {
            let (path, text) = &files[f];
            let mutated = apply(text, &mutations);
            match parse(&mutated, path) {
                Ok(()) => valid.set(valid.get() + 1),
                Err(e) => {
                    errors.set(errors.get() + 1);
                    let name = path.display().to_string();
                    prop_assert!(e.starts_with(&name), "error does not name the file: {e}");
                }
            }
            Ok(())
        })
        .unwrap_or_else(|e| panic!("{e}"));
    // The mutations reach both outcomes (a fuzzer whose every text fails tests one branch).
    let (valid, errors) = (valid.get(), errors.get());
    assert!(errors > 0 && valid > 0, "{valid} valid, {errors} errors");
}

/// A RON error from the syntax: its position, where the parser gives one.
fn located(e: &sim::scenario::ScenarioError) -> Result<String, TestCaseError> {
    let text = e.to_string();
    let syntax = ["Expected", "Unexpected", "expected", "unexpected", "Non-", "invalid", "Invalid"];
    if e.position.is_none() && syntax.iter().any(|s| e.message.starts_with(s)) {
        return Err(TestCaseError::fail(format!("a syntax error without a position: {text}")));
    }
    Ok(text)
}

#[test]
fn scenarios() {
    let mut files = shipped("scenarios", "ron");
    files.extend(shipped("scenarios/paper", "ron"));
    files.extend(shipped("suites/scenarios", "ron"));
    fuzz(&files, |text, path| {
        let scenario = match sim::Scenario::from_ron(text, path) {
            Ok(s) => s,
            Err(e) => return Err(located(&e).map_err(|e| e.to_string())?),
        };
        playback::scenario::RunSpec::from_scenario(scenario, &Default::default())
            .map(|_| ())
            .map_err(|e| format!("{e:#}"))
    });
}

#[test]
fn suites_sweeps_and_claims() {
    let err = |e: sim::scenario::ScenarioError| located(&e).map_err(|e| e.to_string());
    fuzz(&shipped("suites", "ron"), |text, path| {
        tools::suite::Suite::from_ron(text, path).map(|_| ()).or_else(|e| Err(err(e)?))
    });
    fuzz(&shipped("sweeps", "ron"), |text, path| {
        tools::sweep::Sweep::from_ron(text, path).map(|_| ()).or_else(|e| Err(err(e)?))
    });
    fuzz(&shipped("claims", "ron"), |text, path| {
        tools::reproduce::Claims::from_ron(text, path).map(|_| ()).or_else(|e| Err(err(e)?))
    });
}

#[test]
fn density_grids_and_obj_bounds() {
    // Errors read FILE:LINE: what was found, what was expected.
    let at_line = |e: String, path: &Path| {
        let rest = e.strip_prefix(&format!("{}:", path.display())).unwrap_or("");
        let line = rest.split(':').next().unwrap_or("");
        if line.parse::<usize>().is_ok() { e } else { format!("no line number in: {e}") }
    };
    fuzz(&shipped("scenarios/assets", "density"), |text, path| {
        let grid = scene::RawGrid::parse(text, &path.display().to_string())
            .map_err(|e| at_line(e, path))?;
        let (x, y, z) = grid.res;
        assert_eq!(grid.data.len() as u32, x * y * z);
        assert!(grid.data.iter().all(|v| (0.0..=1.0).contains(v)));
        Ok(())
    });
    fuzz(&shipped("scenarios/assets", "obj"), |text, path| {
        let mesh = scene::ClosedMesh::parse_obj(text, &path.display().to_string())
            .map_err(|e| at_line(e, path))?;
        let n = mesh.positions.len() as u32;
        assert!(mesh.triangles.iter().flatten().all(|&i| i < n));
        Ok(())
    });
}
