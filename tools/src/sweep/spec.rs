//! Sweep files (RON). Errors carry the file, line and column, as suite files' do: `cases`,
//! `grid` and `list` are kept as raw entries with their place in the file and parsed one by one
//! (`crate::ron_file`).
//!
//! ```ron
//! Sweep(
//!     cases: [(name: "cornell", scenario: "../suites/scenarios/smoke_cornell.ron", seeds: [1, 2],
//!              frames: 4, resolution: (32, 18), methods: ["taa"])],
//!     // every combination (the last parameter varies fastest) ...
//!     grid: [("taa.alpha", [0.1, 0.2]), ("taa.jitter_length", [8, 16])],
//!     // ... or the listed points: list: [[("taa.alpha", 0.1)], [("taa.alpha", 0.2), ("taa.jitter_length", 4)]],
//! )
//! ```

use std::path::{Path, PathBuf};

use serde::Deserialize;
use sim::scenario::{MethodEntry, ScenarioError};

use crate::ron_file::{self, RonFile};
use crate::suite::spec::Case;

/// One parameter: `METHOD_LABEL.field.subfield` of a case's method, and its value.
#[derive(Clone, Debug, PartialEq)]
pub struct Setting {
    pub param: String,
    pub value: serde_json::Value,
}

/// One point of the sweep: the settings applied together, and where the file wrote them.
#[derive(Clone, Debug, PartialEq)]
pub struct Point {
    pub settings: Vec<Setting>,
    /// The grid entries or the list entry this point came from (for errors).
    pub entries: Vec<MethodEntry>,
}

impl Point {
    /// `taa.alpha=0.1 taa.jitter_length=8`; `default` for the point without settings.
    pub fn label(&self) -> String {
        if self.settings.is_empty() {
            return "default".into();
        }
        self.settings
            .iter()
            .map(|s| format!("{}={}", s.param, value_text(&s.value)))
            .collect::<Vec<_>>()
            .join(" ")
    }
}

/// A value as written in labels: strings without quotes, numbers as JSON writes them.
pub fn value_text(v: &serde_json::Value) -> String {
    match v {
        serde_json::Value::String(s) => s.clone(),
        other => other.to_string(),
    }
}

#[derive(Deserialize)]
#[serde(rename = "Sweep", deny_unknown_fields)]
struct SweepFile {
    #[serde(default)]
    name: Option<String>,
    cases: Vec<Box<ron::value::RawValue>>,
    #[serde(default)]
    grid: Option<Vec<Box<ron::value::RawValue>>>,
    #[serde(default)]
    list: Option<Vec<Box<ron::value::RawValue>>>,
}

#[derive(Clone, Debug)]
pub struct Sweep {
    /// Defaults to the file's stem.
    pub name: String,
    pub cases: Vec<Case>,
    /// The parameter points, in order (one point without settings when the file has neither
    /// `grid` nor `list`: a sweep over cases and seeds only).
    pub points: Vec<Point>,
    pub origin: PathBuf,
}

/// A RON value as JSON (what method settings are set through, `param`).
fn to_json(v: &ron::Value) -> Result<serde_json::Value, String> {
    serde_json::to_value(v).map_err(|e| format!("value {v:?}: {e}"))
}

fn check_param(p: &str) -> Result<(), String> {
    let parts: Vec<&str> = p.split('.').collect();
    if parts.len() < 2 || parts.iter().any(|s| s.is_empty()) {
        return Err(format!(
            "parameter '{p}'; expected METHOD_LABEL.field (e.g. \"taa.alpha\" or \"nirc_blend_1spp.cache.reliability.kappa\")"
        ));
    }
    Ok(())
}

impl Sweep {
    pub fn load(path: &Path) -> Result<Sweep, ScenarioError> {
        Self::from_ron(&ron_file::read(path, "sweep file")?, path)
    }

    pub fn from_ron(text: &str, origin: &Path) -> Result<Sweep, ScenarioError> {
        let file = RonFile { text, origin };
        let parsed: SweepFile = file.parse()?;
        // An entry's parse error, with what the entry should have looked like.
        let expected = |hint: &str| {
            let hint = hint.to_string();
            move |mut e: ScenarioError| {
                e.message = format!("{}; expected {hint}", e.message);
                e
            }
        };
        let cases = crate::suite::spec::parse_cases(file, &parsed.cases, false)?;
        let points = match (&parsed.grid, &parsed.list) {
            (Some(_), Some(_)) => {
                let (line, col) = sim::scenario::line_col(text, text.find("list").unwrap_or(0));
                return Err(file.error(Some((line, col)), "both `grid` and `list`; expected one of them (a grid of every combination, or a list of points)".into()));
            }
            (Some(grid), None) => {
                let mut axes: Vec<(MethodEntry, String, Vec<serde_json::Value>)> = Vec::new();
                for entry in file.entries("grid", grid) {
                    let (param, values): (String, Vec<ron::Value>) = file
                        .entry(&entry)
                        .map_err(expected("a grid axis (\"METHOD_LABEL.field\", [value, ...])"))?;
                    check_param(&param).map_err(|m| file.error_at(&entry, m))?;
                    if values.is_empty() {
                        return Err(file.error_at(
                            &entry,
                            format!(
                                "grid axis '{param}' has no values; expected e.g. (\"{param}\", [0.5, 1.0])"
                            ),
                        ));
                    }
                    if axes.iter().any(|(_, p, _)| *p == param) {
                        return Err(file.error_at(
                            &entry,
                            format!("grid names '{param}' twice; expected one axis per parameter"),
                        ));
                    }
                    let values = values
                        .iter()
                        .map(to_json)
                        .collect::<Result<Vec<_>, _>>()
                        .map_err(|m| file.error_at(&entry, m))?;
                    axes.push((entry, param, values));
                }
                if axes.is_empty() {
                    return Err(file.error(
                        None,
                        "`grid` is empty; expected e.g. grid: [(\"taa.alpha\", [0.1, 0.2])]".into(),
                    ));
                }
                // Row-major: the last axis varies fastest.
                let mut points = vec![Point { settings: vec![], entries: vec![] }];
                for (entry, param, values) in &axes {
                    points = points
                        .into_iter()
                        .flat_map(|p| {
                            values.iter().map(move |v| {
                                let mut q = p.clone();
                                q.settings.push(Setting { param: param.clone(), value: v.clone() });
                                q.entries.push(entry.clone());
                                q
                            })
                        })
                        .collect();
                }
                points
            }
            (None, Some(list)) => {
                let mut points = Vec::new();
                for entry in file.entries("list", list) {
                    let settings: Vec<(String, ron::Value)> = file
                        .entry(&entry)
                        .map_err(expected("a point [(\"METHOD_LABEL.field\", value), ...]"))?;
                    let mut point = Point { settings: vec![], entries: vec![entry.clone()] };
                    for (param, value) in settings {
                        check_param(&param).map_err(|m| file.error_at(&entry, m))?;
                        if point.settings.iter().any(|s| s.param == param) {
                            return Err(
                                file.error_at(&entry, format!("the point sets '{param}' twice"))
                            );
                        }
                        point.settings.push(Setting {
                            param,
                            value: to_json(&value).map_err(|m| file.error_at(&entry, m))?,
                        });
                    }
                    if points.iter().any(|p: &Point| p.settings == point.settings) {
                        return Err(file
                            .error_at(&entry, format!("point {} is listed twice", point.label())));
                    }
                    points.push(point);
                }
                if points.is_empty() {
                    return Err(file.error(
                        None,
                        "`list` is empty; expected e.g. list: [[(\"taa.alpha\", 0.1)]]".into(),
                    ));
                }
                points
            }
            (None, None) => vec![Point { settings: vec![], entries: vec![] }],
        };
        let name = file.name_or_stem(parsed.name, "sweep");
        Ok(Sweep { name, cases, points, origin: origin.to_path_buf() })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn grid_is_row_major_and_list_keeps_order() {
        let text = "Sweep(cases: [(name: \"a\", scenario: \"s.ron\", seeds: [1])],\n grid: [(\"taa.alpha\", [0.1, 0.2]), (\"taa.jitter_length\", [8, 16])])";
        let s = Sweep::from_ron(text, Path::new("x/sw.ron")).unwrap();
        let labels: Vec<String> = s.points.iter().map(Point::label).collect();
        assert_eq!(
            labels,
            [
                "taa.alpha=0.1 taa.jitter_length=8",
                "taa.alpha=0.1 taa.jitter_length=16",
                "taa.alpha=0.2 taa.jitter_length=8",
                "taa.alpha=0.2 taa.jitter_length=16"
            ]
        );
        assert_eq!(s.name, "sw");
        assert_eq!(s.cases[0].scenario, Path::new("x/s.ron"));
        let text = "Sweep(cases: [(name: \"a\", scenario: \"s.ron\", seeds: [1])],\n list: [[(\"taa.alpha\", 0.5)], [(\"taa.alpha\", 0.1), (\"taa.clamp\", \"None\")]])";
        let s = Sweep::from_ron(text, Path::new("sw.ron")).unwrap();
        let labels: Vec<String> = s.points.iter().map(Point::label).collect();
        assert_eq!(labels, ["taa.alpha=0.5", "taa.alpha=0.1 taa.clamp=None"]);
    }

    #[test]
    fn errors_name_file_line_and_column() {
        let head = "Sweep(\n    cases: [(name: \"a\", scenario: \"s.ron\", seeds: [1])],\n";
        let cases = [
            (format!("{head}    grid: [\n        (\"taa.alpha\", []),\n    ],\n)"), 4, "no values"),
            (format!("{head}    grid: [\n        (\"alpha\", [0.1]),\n    ],\n)"), 4, "METHOD_LABEL.field"),
            (format!("{head}    grid: [\n        (\"taa.alpha\", 0.1),\n    ],\n)"), 4, "grid axis"),
            (format!("{head}    list: [\n        [(\"taa.alpha\", 0.1)],\n        [(\"taa.alpha\", 0.1)],\n    ],\n)"), 5, "listed twice"),
            (format!("{head}    grdi: [],\n)"), 3, "grdi"),
            ("Sweep(\n    cases: [\n        (name: \"a\", scenario: \"s.ron\", seeds: []),\n    ],\n)".to_string(), 3, "no seeds"),
        ];
        for (text, line, what) in cases {
            let e = Sweep::from_ron(&text, Path::new("sweeps/bad.ron")).unwrap_err().to_string();
            assert!(e.starts_with(&format!("sweeps/bad.ron:{line}:")), "{e}\n{text}");
            assert!(e.contains(what), "{e}");
        }
    }
}
