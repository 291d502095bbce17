//! A history read back as series: per (kind, scale, adapter, claim) one point per commit, in
//! the order the commits were first recorded, each compared with the commit before it. Two
//! flags: the verdict changed, or the value moved by more than the margin while the verdict
//! held (a bench ratio: by more than its run-to-run spread).

use std::collections::BTreeMap;

use super::record::{Entry, Kind, Record};

/// What a series is about.
#[derive(Clone, Debug, PartialEq, Eq, PartialOrd, Ord)]
pub struct Key {
    pub kind: Kind,
    pub scale: String,
    pub adapter: String,
    pub id: String,
}

/// What changed from the commit before.
#[derive(Clone, Debug, PartialEq)]
pub enum Flag {
    VerdictChanged {
        from: String,
        to: String,
    },
    /// |value − previous| above the margin while the verdict held.
    Drift {
        change: f64,
        margin: f64,
    },
}

impl Flag {
    pub fn describe(&self) -> String {
        match self {
            Flag::VerdictChanged { from, to } => format!("verdict changed: {from} -> {to}"),
            Flag::Drift { change, margin } => {
                format!("drift {change:+.4} beyond margin {margin:.4}")
            }
        }
    }
}

/// One commit's point of a series: the latest record of that commit, with the values of every
/// record of it (repeats give the run-to-run spread).
#[derive(Clone, Debug, PartialEq)]
pub struct Point {
    pub commit: String,
    pub dirty: bool,
    pub date: String,
    pub profile: String,
    pub entry: Entry,
    pub repeats: Vec<f64>,
    pub flags: Vec<Flag>,
}

impl Point {
    /// `abc1234` or `abc1234-dirty`.
    pub fn label(&self) -> String {
        commit_label(&self.commit, self.dirty)
    }
}

/// A commit as a short label: `abc1234` or `abc1234-dirty`.
fn commit_label(commit: &str, dirty: bool) -> String {
    let c: String = commit.chars().take(7).collect();
    if dirty { format!("{c}-dirty") } else { c }
}

#[derive(Clone, Debug, PartialEq)]
pub struct Series {
    pub key: Key,
    pub points: Vec<Point>,
}

impl Series {
    /// The flags of the latest commit against the one before it.
    pub fn latest_flags(&self) -> &[Flag] {
        self.points.last().map_or(&[], |p| &p.flags)
    }
}

/// Twice the pooled standard deviation of repeated values at one commit (runs of one build on
/// one adapter): the run-to-run spread; `None` when no commit was measured twice.
fn repeat_spread(points: &[Point]) -> Option<f64> {
    let (mut ss, mut dof) = (0.0, 0usize);
    for p in points.iter().filter(|p| p.repeats.len() >= 2) {
        let n = p.repeats.len();
        let mean = p.repeats.iter().sum::<f64>() / n as f64;
        ss += p.repeats.iter().map(|v| (v - mean).powi(2)).sum::<f64>();
        dof += n - 1;
    }
    (dof > 0).then(|| 2.0 * (ss / dof as f64).sqrt())
}

/// The margin of a step from `a` to `b`: the larger of the two records' margins (a change
/// within either run's own noise or tolerance is no drift); for a series without recorded
/// margins (bench ratios without rounds), the run-to-run spread of repeats.
fn step_margin(a: &Entry, b: &Entry, spread: Option<f64>) -> Option<f64> {
    let m = match (a.margin, b.margin) {
        (Some(x), Some(y)) => Some(x.max(y)),
        (x, y) => x.or(y),
    };
    match (m, spread) {
        (Some(m), Some(s)) => Some(m.max(s)),
        (m, s) => m.or(s),
    }
}

/// The flags of the step from `a` to `b`.
pub fn flags(a: &Entry, b: &Entry, spread: Option<f64>) -> Vec<Flag> {
    if a.verdict != b.verdict {
        return vec![Flag::VerdictChanged {
            from: a.verdict.clone().unwrap_or_else(|| "-".into()),
            to: b.verdict.clone().unwrap_or_else(|| "-".into()),
        }];
    }
    match (a.value, b.value, step_margin(a, b, spread)) {
        (Some(x), Some(y), Some(margin)) if (y - x).abs() > margin => {
            vec![Flag::Drift { change: y - x, margin }]
        }
        _ => Vec::new(),
    }
}

/// The series of `records` (in the order read: by date), each commit's point flagged against
/// the commit before.
pub fn series(records: &[Record]) -> Vec<Series> {
    let mut by_key: BTreeMap<Key, Vec<Point>> = BTreeMap::new();
    for r in records {
        for e in &r.entries {
            let key = Key {
                kind: r.kind,
                scale: r.scale.clone(),
                adapter: r.adapter.clone(),
                id: e.id.clone(),
            };
            let points = by_key.entry(key).or_default();
            let same = |p: &Point| p.commit == r.commit && p.dirty == r.dirty;
            match points.iter_mut().find(|p| same(p)) {
                Some(p) => {
                    p.date = r.date.clone();
                    p.profile = r.profile.clone();
                    p.entry = e.clone();
                    p.repeats.extend(e.value);
                }
                None => points.push(Point {
                    commit: r.commit.clone(),
                    dirty: r.dirty,
                    date: r.date.clone(),
                    profile: r.profile.clone(),
                    entry: e.clone(),
                    repeats: e.value.into_iter().collect(),
                    flags: Vec::new(),
                }),
            }
        }
    }
    by_key
        .into_iter()
        .map(|(key, mut points)| {
            let spread = repeat_spread(&points);
            for i in 1..points.len() {
                points[i].flags = flags(&points[i - 1].entry, &points[i].entry, spread);
            }
            Series { key, points }
        })
        .collect()
}

fn number(v: Option<f64>) -> String {
    v.map_or("-".into(), |x| format!("{x:.4}"))
}

/// The series as Markdown: one table per series, one row per commit.
pub fn markdown(all: &[Series]) -> String {
    let mut md = String::from("# Results over commits\n");
    for s in all {
        let k = &s.key;
        md.push_str(&format!(
            "\n## {} {} ({}): {}\n\n| commit | date | build | value [interval] | margin | verdict | flag |\n|---|---|---|---|---|---|---|\n",
            k.kind.name(),
            k.scale,
            k.adapter,
            k.id
        ));
        for p in &s.points {
            let e = &p.entry;
            let interval = match (e.lo, e.hi) {
                (Some(lo), Some(hi)) => format!(" [{lo:.4}, {hi:.4}]"),
                _ => String::new(),
            };
            let flag = p.flags.iter().map(Flag::describe).collect::<Vec<_>>().join("; ");
            md.push_str(&format!(
                "| {} | {} | {} | {}{interval} | {} | {} | {} |\n",
                p.label(),
                p.date,
                p.profile,
                number(e.value),
                number(e.margin),
                e.verdict.as_deref().unwrap_or("-"),
                if flag.is_empty() { "-".into() } else { format!("**{flag}**") },
            ));
        }
    }
    md
}

/// A series' chart: value and interval bounds against the commit's position, a marker at each
/// flagged commit.
pub fn chart(s: &Series) -> report::charts::Chart {
    use report::charts::{Chart, Kind as ChartKind, Series as Line};
    let line = |name: &str, f: &dyn Fn(&Entry) -> Option<f64>| Line {
        name: name.into(),
        points: s
            .points
            .iter()
            .enumerate()
            .filter_map(|(i, p)| f(&p.entry).map(|v| (i as f64, v)))
            .collect(),
    };
    let series = vec![
        line("value", &|e| e.value),
        line("interval low", &|e| e.lo),
        line("interval high", &|e| e.hi),
    ]
    .into_iter()
    .filter(|l| !l.points.is_empty())
    .collect();
    let events = s
        .points
        .iter()
        .enumerate()
        .filter(|(_, p)| !p.flags.is_empty())
        .map(|(i, p)| {
            let what = if p.flags.iter().any(|f| matches!(f, Flag::VerdictChanged { .. })) {
                "verdict"
            } else {
                "drift"
            };
            (i as f64, format!("{} {what}", p.label()))
        })
        .collect();
    Chart {
        title: format!("{} {}: {}", s.key.kind.name(), s.key.scale, s.key.id),
        x_label: format!(
            "commit ({})",
            s.points.iter().map(Point::label).collect::<Vec<_>>().join(", ")
        ),
        y_label: "value".into(),
        kind: ChartKind::Lines,
        series,
        events,
        pareto: Vec::new(),
        x_extent: vec![0.0, (s.points.len().max(2) - 1) as f64],
    }
}

/// A ratio of `now` against the last kept record of the same command, form, build and adapter.
#[derive(Clone, Debug, PartialEq)]
pub struct Change {
    pub id: String,
    /// The last kept record's value and its commit label.
    pub last: f64,
    pub last_commit: String,
    pub now: f64,
    /// The run-to-run spread the change is read against: the larger of the two records' margins
    /// (half the range of a run's rounds) and twice the pooled standard deviation of repeated
    /// runs at one commit over the series; none when neither is known.
    pub spread: Option<f64>,
}

impl Change {
    /// The change is beyond the run-to-run spread.
    pub fn beyond_spread(&self) -> bool {
        self.spread.is_some_and(|s| (self.now - self.last).abs() > s)
    }
}

/// Each ratio of `now` against the last record of `history` (ordered by date, `now` not in
/// it) from the same kind, name, build profile and adapter that has the ratio.
pub fn against_last(history: &[Record], now: &Record) -> Vec<Change> {
    let same = |r: &Record| {
        r.kind == now.kind
            && r.name == now.name
            && r.profile == now.profile
            && r.adapter == now.adapter
    };
    let mut with_now: Vec<Record> = history.iter().filter(|r| same(r)).cloned().collect();
    with_now.push(now.clone());
    let all = series(&with_now);
    let mut out = Vec::new();
    for e in &now.entries {
        let Some(value) = e.value else { continue };
        let Some((r, last)) = history.iter().rev().filter(|r| same(r)).find_map(|r| {
            r.entries.iter().find(|x| x.id == e.id && x.value.is_some()).map(|x| (r, x))
        }) else {
            continue;
        };
        let repeats = all.iter().find(|s| s.key.id == e.id).and_then(|s| repeat_spread(&s.points));
        let spread = match (step_margin(last, e, None), repeats) {
            (Some(m), Some(s)) => Some(m.max(s)),
            (m, s) => m.or(s),
        };
        out.push(Change {
            id: e.id.clone(),
            last: last.value.unwrap_or(f64::NAN),
            last_commit: commit_label(&r.commit, r.dirty),
            now: value,
            spread,
        });
    }
    out
}

/// The changes as a Markdown table (what `flicker bench` prints after its own table).
pub fn changes_markdown(changes: &[Change]) -> String {
    if changes.is_empty() {
        return "\nNo earlier record of this bench, build and adapter in the results history: nothing to compare with.\n".into();
    }
    let mut md = String::from(
        "\n## Against the last kept record\n\n| ratio | last (commit) | now | change | run-to-run spread | |\n|---|---|---|---|---|---|\n",
    );
    for c in changes {
        let change = c.now - c.last;
        let rel = if c.last != 0.0 {
            format!(" ({:+.1}%)", 100.0 * change / c.last)
        } else {
            String::new()
        };
        md.push_str(&format!(
            "| {} | {:.4} ({}) | {:.4} | {change:+.4}{rel} | {} | {} |\n",
            c.id,
            c.last,
            c.last_commit,
            c.now,
            c.spread.map_or("unknown (no rounds or repeats yet)".into(), |s| format!("{s:.4}")),
            if c.beyond_spread() {
                "**beyond the spread**"
            } else if c.spread.is_some() {
                "within"
            } else {
                "-"
            },
        ));
    }
    md
}
