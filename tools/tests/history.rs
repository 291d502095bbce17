//! The results history: records appended and read back across commits, a verdict change and a
//! drift beyond the margin flagged (and nothing flagged within it), concurrent writers losing
//! nothing, a damaged file named with its line, and each command's entries (a claim's value,
//! interval and margin; the bench's ratios).

use tools::history::series::{Flag, series};
use tools::history::sources::{bench_speed_entries, claim_entry, claim_estimate};
use tools::history::{Entry, Kind, Record, append, read};
use tools::reproduce::{Claims, Judged, Verdict};

fn temp(name: &str) -> tempfile::TempDir {
    tempfile::Builder::new().prefix(&format!("flicker-history-{name}-")).tempdir().unwrap()
}

fn entry(id: &str, value: f64, half: f64, verdict: &str, margin: f64) -> Entry {
    Entry {
        id: id.into(),
        value: Some(value),
        lo: Some(value - half),
        hi: Some(value + half),
        verdict: Some(verdict.into()),
        margin: Some(margin),
        margin_from: "the claim's tolerance".into(),
        detail: String::new(),
    }
}

fn record(commit: &str, date: &str, entries: Vec<Entry>) -> Record {
    Record {
        version: tools::history::record::FORMAT,
        kind: Kind::Reproduce,
        name: "all".into(),
        scale: "lab".into(),
        commit: commit.into(),
        dirty: false,
        profile: "release".into(),
        adapter: "llvmpipe / Vulkan".into(),
        date: date.into(),
        command: "flicker reproduce all --scale lab".into(),
        entries,
    }
}

const DAY1: &str = "2026-12-01T10:00:00Z";
const DAY2: &str = "2026-12-02T10:00:00Z";
const DAY3: &str = "2026-12-03T10:00:00Z";

#[test]
fn records_of_two_commits_read_back_in_order() {
    let tmp = temp("two");
    let dir = tmp.path().to_path_buf();
    // Written newest first: the reader orders by date, not by when the file appeared.
    // Binary fractions: serde_json (without its `float_roundtrip` feature) may read a decimal
    // back one unit in the last place off.
    let second = record("bbbbbbb2", DAY2, vec![entry("p/c", 0.5, 0.0078125, "reproduced", 0.0625)]);
    let first = record("aaaaaaa1", DAY1, vec![entry("p/c", 0.25, 0.0078125, "reproduced", 0.0625)]);
    let p2 = append(&dir, &second).unwrap();
    let p1 = append(&dir, &first).unwrap();
    assert!(p1.starts_with(dir.join("reproduce/lab")), "{}", p1.display());
    let back = read(&dir).unwrap();
    assert_eq!(back, vec![(p1, first.clone()), (p2, second.clone())]);
    let s = series(&[first, second]);
    assert_eq!(s.len(), 1);
    let commits: Vec<&str> = s[0].points.iter().map(|p| p.commit.as_str()).collect();
    assert_eq!(commits, ["aaaaaaa1", "bbbbbbb2"]);
    assert_eq!(s[0].points[1].entry.value, Some(0.5));
}

#[test]
fn a_changed_verdict_is_flagged() {
    let records = [
        record("a1", DAY1, vec![entry("p/c", 0.1, 0.01, "reproduced", 0.5)]),
        record("b2", DAY2, vec![entry("p/c", 0.1, 0.01, "reproduced", 0.5)]),
        // Well within the margin, but the outcome is another.
        record("c3", DAY3, vec![entry("p/c", 0.1001, 0.01, "inconclusive", 0.5)]),
    ];
    let s = series(&records);
    assert_eq!(s[0].points[1].flags, vec![]);
    assert_eq!(
        s[0].latest_flags(),
        [Flag::VerdictChanged { from: "reproduced".into(), to: "inconclusive".into() }]
    );
}

#[test]
fn a_drift_beyond_the_margin_is_flagged_while_the_verdict_holds() {
    let at = |values: [f64; 3]| {
        let r: Vec<Record> = [("a1", DAY1), ("b2", DAY2), ("c3", DAY3)]
            .iter()
            .zip(values)
            .map(|((c, d), v)| record(c, d, vec![entry("p/c", v, 0.001, "reproduced", 0.05)]))
            .collect();
        series(&r).remove(0)
    };
    // 0.10 -> 0.14 moves less than the margin 0.05; 0.14 -> 0.20 moves more.
    let s = at([0.10, 0.14, 0.20]);
    assert_eq!(s.points[1].flags, vec![]);
    match s.latest_flags() {
        [Flag::Drift { change, margin }] => {
            assert!((change - 0.06).abs() < 1e-12 && *margin == 0.05, "{change} {margin}");
        }
        other => panic!("expected a drift, got {other:?}"),
    }
    // Downwards too.
    assert!(matches!(at([0.20, 0.20, 0.10]).latest_flags(), [Flag::Drift { .. }]));
    // The larger of two records' margins: a run that was itself noisier excuses more.
    let mut r = vec![
        record("a1", DAY1, vec![entry("p/c", 0.1, 0.001, "reproduced", 0.05)]),
        record("b2", DAY2, vec![entry("p/c", 0.2, 0.001, "reproduced", 0.2)]),
    ];
    assert_eq!(series(&r)[0].latest_flags(), []);
    // Without a recorded margin (a bench ratio without rounds), repeats at one commit give
    // the run-to-run spread: 2 sd of {1.0, 1.1} = 0.141, so 1.05 -> 1.5 drifts.
    r = ["1.0", "1.1", "1.5"]
        .iter()
        .zip([("a1", DAY1), ("a1", DAY2), ("b2", DAY3)])
        .map(|(v, (c, d))| {
            let mut e = entry("ratio", v.parse().unwrap(), 0.0, "-", 0.0);
            (e.margin, e.lo, e.hi, e.verdict) = (None, None, None, None);
            record(c, d, vec![e])
        })
        .collect();
    let s = series(&r).remove(0);
    assert_eq!(s.points.len(), 2, "one point per commit");
    assert!(
        matches!(s.latest_flags(), [Flag::Drift { margin, .. }] if (margin - 0.1414).abs() < 1e-3)
    );
}

#[test]
fn concurrent_writers_lose_no_record() {
    let tmp = temp("concurrent");
    let dir = tmp.path().to_path_buf();
    // Threads of one process share its id and, here, the date and commit: the hardest case for
    // unique names.
    let threads = 8;
    let each = 25;
    std::thread::scope(|s| {
        for t in 0..threads {
            let dir = &dir;
            s.spawn(move || {
                for i in 0..each {
                    let e = entry(&format!("t{t}/i{i}"), i as f64, 0.1, "reproduced", 0.1);
                    append(dir, &record("a1", DAY1, vec![e])).unwrap();
                }
            });
        }
    });
    let back = read(&dir).unwrap();
    assert_eq!(back.len(), threads * each);
    let mut ids: Vec<String> = back.iter().map(|(_, r)| r.entries[0].id.clone()).collect();
    ids.sort();
    ids.dedup();
    assert_eq!(ids.len(), threads * each, "a record was overwritten");
}

#[test]
fn a_damaged_file_is_named_with_its_line() {
    let tmp = temp("damaged");
    let dir = tmp.path().to_path_buf();
    let good = append(&dir, &record("a1", DAY1, vec![entry("p/c", 0.1, 0.01, "reproduced", 0.05)]))
        .unwrap();
    let text = std::fs::read_to_string(&good).unwrap();
    // A value that is no number, on the line of "value".
    let line = text.lines().position(|l| l.contains("\"value\"")).unwrap() + 1;
    let bad = good.with_file_name("damaged.json");
    std::fs::write(&bad, text.replace("\"value\": 0.1", "\"value\": \"high\"")).unwrap();
    let e = read(&dir).unwrap_err().to_string();
    assert!(e.contains(&format!("{}:{line}:", bad.display())), "{e}");
    // A file cut short (a copy interrupted on a shared disk).
    std::fs::write(&bad, &text[..text.len() / 2]).unwrap();
    let e = read(&dir).unwrap_err().to_string();
    assert!(e.contains(&format!("{}:", bad.display())) && e.contains("EOF"), "{e}");
    // A writer's temporary file is not a record.
    std::fs::remove_file(&bad).unwrap();
    std::fs::write(good.with_extension("json.tmp123"), "{").unwrap();
    assert_eq!(read(&dir).unwrap().len(), 1);
}

fn claims() -> Claims {
    let root = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).parent().unwrap();
    let text = "Claims(\n    paper: \"x\",\n    title: \"x\",\n    cases: [\n        (name: \"corridor\", scenario: \"../suites/scenarios/papers_termination_corridor.ron\", seeds: [3, 4]),\n    ],\n    claims: [\n        (id: \"below\", claim: \"c\", source: \"s\", paper: \"p\", case: \"corridor\", statistic: (metric: PathLength, window: Overall), comparison: Below(method: \"vb_rel_0.1\", than: \"vb_rel_1\"), smallest_effect: Relative(0.1), smallest_effect_from: \"an argued share\"),\n        (id: \"value\", claim: \"c\", source: \"s\", paper: \"p\", case: \"corridor\", statistic: (metric: PathLength, window: Overall), comparison: Value(method: \"vb_rel_0.1\", value: 2.0), smallest_effect: Absolute(0.25), smallest_effect_from: \"paper\"),\n    ],\n)\n";
    Claims::from_ron(text, &root.join("claims/x.ron")).unwrap()
}

#[test]
fn a_claim_entry_holds_its_value_interval_and_margin() {
    let c = claims();
    // Below: per-seed a then b; the value is the mean paired difference a - b.
    let judged = Judged {
        flicker: "f".into(),
        verdict: Verdict::Reproduced,
        values: vec![1.0, 1.2, 1.1, 2.0, 2.4, 2.0],
    };
    let e = claim_entry("x", &c.claims[0], &judged);
    assert_eq!(e.id, "x/below");
    // Differences -1.0, -1.2, -0.9: mean -1.0333, sd 0.1528; the judge's one-sided 95% bound,
    // t(0.95, 2) = 2.920.
    let half = 2.919_986 * 0.152_752_5 / 3f64.sqrt();
    assert!((e.value.unwrap() + 1.033_333).abs() < 1e-5, "{e:?}");
    assert!((e.hi.unwrap() - e.value.unwrap() - half).abs() < 1e-4, "{e:?}");
    assert!((e.value.unwrap() - e.lo.unwrap() - half).abs() < 1e-4, "{e:?}");
    // Relative(0.1) of the second method's mean, (2.0 + 2.4 + 2.0) / 3.
    assert!((e.margin.unwrap() - 0.1 * 6.4 / 3.0).abs() < 1e-9, "the claim's smallest effect");
    assert_eq!(e.margin_from, "an argued share");
    assert_eq!(e.verdict.as_deref(), Some("reproduced"));
    // Value: the per-seed values; the margin is the claim's absolute smallest effect.
    let judged =
        Judged { flicker: "f".into(), verdict: Verdict::NotReproduced, values: vec![2.0, 2.2] };
    let e = claim_entry("x", &c.claims[1], &judged);
    assert!((e.value.unwrap() - 2.1).abs() < 1e-12);
    assert_eq!(e.margin, Some(0.25));
    assert_eq!(e.verdict.as_deref(), Some("not reproduced"));
    // Nothing measured: no value, the verdict kept.
    let none = Judged {
        flicker: "-".into(),
        verdict: Verdict::NotComparable("not played".into()),
        values: vec![],
    };
    assert_eq!(claim_estimate(&c.claims[0].comparison, &none), None);
    assert_eq!(claim_entry("x", &c.claims[0], &none).verdict.as_deref(), Some("not comparable"));
}

#[test]
fn the_bench_ratios_are_read_from_its_json() {
    let json = serde_json::json!({
        "adapter": {"name": "gpu", "backend": "Vulkan"},
        "traversal": [
            {"scene": "hairball", "traversal_ratio_vs_obvhs": 3.0, "paired_ratios": [2.5, 3.0, 3.5]},
        ],
        "reference_paths_ratio_vs_mitsuba": 0.8,
        "reference_paired_ratios_vs_mitsuba": [0.7, 0.8, 1.0],
    });
    let e = bench_speed_entries(&json);
    let ids: Vec<&str> = e.iter().map(|e| e.id.as_str()).collect();
    assert_eq!(ids, ["traversal/hairball/wgsl_over_obvhs", "reference/paths_over_mitsuba"]);
    assert_eq!(
        (e[0].value, e[0].lo, e[0].hi, e[0].margin),
        (Some(3.0), Some(2.5), Some(3.5), Some(0.5))
    );
    assert_eq!((e[1].value, e[1].lo, e[1].hi), (Some(0.8), Some(0.7), Some(1.0)));
    assert!((e[1].margin.unwrap() - 0.15).abs() < 1e-12, "{:?}", e[1].margin);
    // A record from before the paired rounds: its spread is left to repeated runs.
    let json = serde_json::json!({"traversal": [], "reference_paths_ratio_vs_mitsuba": 0.8});
    let e = bench_speed_entries(&json);
    assert_eq!((e[0].value, e[0].lo, e[0].margin), (Some(0.8), None, None));
    // Mitsuba not installed: no entry rather than a made-up number.
    let json = serde_json::json!({"traversal": [], "reference_paths_ratio_vs_mitsuba": null});
    assert!(bench_speed_entries(&json).is_empty());
}

/// The bench compares each ratio with the last kept record of the same bench, build and
/// adapter, read against the run-to-run spread: repeats at one commit give the spread, a
/// change beyond it is flagged, one within it is not, and another adapter's record is ignored.
#[test]
fn the_bench_compares_with_its_last_record_against_the_spread() {
    use tools::history::series::{against_last, changes_markdown};
    let bench = |commit: &str, date: &str, adapter: &str, value: f64| {
        let mut r = record(
            commit,
            date,
            vec![Entry {
                verdict: None,
                margin: None,
                lo: None,
                hi: None,
                ..entry("reference/paths_over_mitsuba", value, 0.0, "-", 0.0)
            }],
        );
        r.kind = Kind::Bench;
        r.name = "speed".into();
        r.scale = "-".into();
        r.adapter = adapter.into();
        r
    };
    // Commit a measured three times: 0.80, 0.84, 0.82 (sd 0.02, spread 2 sd = 0.04).
    let mut history = vec![
        bench("aaaaaaa1", DAY1, "llvmpipe / Vulkan", 0.80),
        bench("aaaaaaa1", DAY1, "llvmpipe / Vulkan", 0.84),
        bench("aaaaaaa1", DAY1, "llvmpipe / Vulkan", 0.82),
    ];
    // A later record on another adapter is not this bench's last record.
    history.push(bench("ccccccc3", DAY2, "NVIDIA H100 / Vulkan", 2.5));
    let loss = bench("bbbbbbb2", DAY3, "llvmpipe / Vulkan", 0.70);
    let c = against_last(&history, &loss);
    assert_eq!(c.len(), 1);
    assert_eq!((c[0].last, c[0].last_commit.as_str(), c[0].now), (0.82, "aaaaaaa", 0.70));
    assert!((c[0].spread.unwrap() - 0.04).abs() < 1e-9, "{:?}", c[0].spread);
    assert!(c[0].beyond_spread(), "a loss of 0.12 against a spread of 0.04");
    assert!(changes_markdown(&c).contains("**beyond the spread**"));
    let same = bench("bbbbbbb2", DAY3, "llvmpipe / Vulkan", 0.85);
    assert!(!against_last(&history, &same)[0].beyond_spread(), "0.03 is within 0.04");
    // No earlier record of this adapter: nothing to compare, and the page says so.
    let other = bench("bbbbbbb2", DAY3, "AMD / Vulkan", 1.0);
    assert!(against_last(&history, &other).is_empty());
    assert!(changes_markdown(&[]).contains("nothing to compare with"));
}
