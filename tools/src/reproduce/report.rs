//! reproduce.md and reproduce.html: per paper a conclusion built from its claims (counts per
//! verdict, what holds, what fails and the departure its claims file names first, what is
//! open), then one row per claim: the paper's number beside flicker's (both methods named)
//! with its interval, the verdict and the known departures.

use maud::{PreEscaped, html};

use super::claims::{Claim, Claims, Comparison};
use super::table::{self, CaseTable};
use super::verdict::{Judged, VERDICTS, Verdict};

/// One paper's claims and their outcomes.
pub struct PaperResult<'a> {
    pub claims: &'a Claims,
    pub judged: Vec<(&'a Claim, Judged)>,
    /// Each played case's methods against the claims' statistics.
    pub tables: Vec<CaseTable>,
}

fn cell(s: &str) -> String {
    s.replace('|', "\\|").replace('\n', " ")
}

fn verdict_text(v: &Verdict) -> String {
    v.text()
}

/// The comparison, where it is played (when it is) and the smallest effect with its source.
fn test_text(c: &Claim) -> String {
    let mut t = c.comparison.describe();
    if let Some(case) = &c.case {
        t.push_str(&format!(" on {case}"));
    }
    if let Some(s) = &c.statistic {
        t.push_str(&format!(", {}", s.describe()));
    }
    format!(
        "{t}; smallest effect {} (from: {})",
        c.smallest_effect.describe(),
        c.smallest_effect_from
    )
}

/// `a, b and c`.
fn and_list(items: &[String]) -> String {
    match items {
        [] => String::new(),
        [one] => one.clone(),
        [rest @ .., last] => format!("{} and {last}", rest.join(", ")),
    }
}

/// A paper's conclusion: the counts per verdict, then what holds, what fails (with the
/// departure its claims file names first) and what is open, from the judged claims.
pub fn conclusion(judged: &[(&Claim, Judged)]) -> String {
    let count = |name: &str| judged.iter().filter(|(_, j)| j.verdict.name() == name).count();
    let counts: Vec<String> = VERDICTS.iter().map(|v| format!("{} {v}", count(v))).collect();
    let mut out = format!("{} claims: {}.", judged.len(), counts.join(", "));
    let of = |name: &str| -> Vec<(&Claim, &Judged)> {
        judged.iter().filter(|(_, j)| j.verdict.name() == name).map(|(c, j)| (*c, j)).collect()
    };
    let held: Vec<String> = of(VERDICTS[0]).iter().map(|(c, _)| format!("`{}`", c.id)).collect();
    if !held.is_empty() {
        out.push_str(&format!(" Holds: {}.", and_list(&held)));
    }
    let failed: Vec<String> = of(VERDICTS[1])
        .iter()
        .map(|(c, _)| match c.departures.first() {
            Some(d) => format!("`{}` (its claims file names first: {d})", c.id),
            None => format!("`{}` (its claims file names no departure)", c.id),
        })
        .collect();
    if !failed.is_empty() {
        out.push_str(&format!(" Fails: {}.", and_list(&failed)));
    }
    let open: Vec<String> = of(VERDICTS[2])
        .iter()
        .map(|(c, j)| match j.verdict {
            Verdict::Inconclusive { seeds: Some(n) } => format!("`{}` (about {n} seeds)", c.id),
            _ => format!("`{}` (the mean sits on the margin)", c.id),
        })
        .collect();
    let unjudged: Vec<String> = of(VERDICTS[3])
        .iter()
        .map(|(c, _)| {
            let declared = matches!(c.comparison, Comparison::NotComparable { .. });
            format!("`{}` ({})", c.id, if declared { "not measured by the lab" } else { "no data" })
        })
        .collect();
    match (open.is_empty(), unjudged.is_empty()) {
        (true, true) => {}
        (false, true) => out.push_str(&format!(" Open: {}.", and_list(&open))),
        (true, false) => out.push_str(&format!(" Not judged: {}.", and_list(&unjudged))),
        (false, false) => out.push_str(&format!(
            " Open: {}; not judged: {}.",
            and_list(&open),
            and_list(&unjudged)
        )),
    }
    out
}

/// Each claim judged again with one condition switched, beside the claim it varies:
/// (claim, its verdict, what is switched, the variant's id, the variant's verdict).
fn variants<'a>(judged: &'a [(&'a Claim, Judged)]) -> Vec<[String; 5]> {
    let mut rows = Vec::new();
    for (base, bj) in judged.iter().filter(|(c, _)| c.variant_of.is_none()) {
        for (c, j) in judged {
            if let Some(v) = c.variant_of.as_ref().filter(|v| v.claim == base.id) {
                rows.push([
                    base.id.clone(),
                    verdict_text(&bj.verdict),
                    v.switched.clone(),
                    c.id.clone(),
                    verdict_text(&j.verdict),
                ]);
            }
        }
    }
    rows
}

/// The variants as a Markdown section, or nothing when the paper has none.
fn variants_markdown(judged: &[(&Claim, Judged)]) -> String {
    let rows = variants(judged);
    if rows.is_empty() {
        return String::new();
    }
    let mut md = String::from(
        "\n### With and without each switched condition\n\n| claim | verdict | switched | verdict switched |\n|---|---|---|---|\n",
    );
    for [id, v, switched, vid, vv] in rows {
        md.push_str(&format!(
            "| `{}` | {} | {} (`{}`) | {} |\n",
            cell(&id),
            cell(&v),
            cell(&switched),
            cell(&vid),
            cell(&vv)
        ));
    }
    md.push('\n');
    md
}

/// The Markdown report; `header` says how it was made (command, scale, seeds, commit).
pub fn markdown(header: &str, papers: &[PaperResult]) -> String {
    let mut md = format!("# What the papers claim, and what we measure\n\n{header}\n");
    for p in papers {
        md.push_str(&format!("\n## {}\n\n{}.\n\n", p.claims.paper, p.claims.title));
        md.push_str(&format!("{}\n\n", conclusion(&p.judged)));
        md.push_str(
            "| claim | where | paper | test | flicker (95% interval) | verdict | departures |\n",
        );
        md.push_str("|---|---|---|---|---|---|---|\n");
        for (c, j) in &p.judged {
            md.push_str(&format!(
                "| {} | {} | {} | {} | {} | {} | {} |\n",
                cell(&format!("{}: {}", c.id, c.claim)),
                cell(&c.source),
                cell(&c.paper),
                cell(&test_text(c)),
                cell(&j.flicker),
                cell(&verdict_text(&j.verdict)),
                cell(&c.departures.join("; ")),
            ));
        }
        md.push_str(&variants_markdown(&p.judged));
        for t in &p.tables {
            md.push_str(&table::markdown(t));
        }
    }
    md
}

const STYLE: &str = "body{font-family:sans-serif;margin:2em}table{border-collapse:collapse}td,th{border:1px solid #ccc;padding:4px;vertical-align:top;font-size:90%}.reproduced{background:#d9f2d9}.not-reproduced{background:#f6d5d5}.inconclusive{background:#fdf3cf}.not-comparable{background:#eee}";

/// The same table as a standalone page, verdicts coloured.
pub fn html(header: &str, papers: &[PaperResult]) -> String {
    html! {
        (PreEscaped("<!doctype html>"))
        meta charset="utf-8";
        title { "flicker reproduce" }
        "\n"
        style { (PreEscaped(STYLE)) }
        "\n"
        h1 { "What the papers claim, and what we measure" }
        "\n"
        p { (header) }
        "\n"
        @for p in papers {
            h2 { (p.claims.title) " (" (p.claims.paper) ")" }
            "\n"
            p { (conclusion(&p.judged).replace('`', "")) }
            "\n"
            table {
                tr {
                    th { "claim" } th { "where" } th { "paper" } th { "test" }
                    th { "flicker (95% interval)" } th { "verdict" } th { "departures" }
                }
                "\n"
                @for (c, j) in &p.judged {
                    tr {
                        td { b { (c.id) } ": " (c.claim) }
                        td { (c.source) } td { (c.paper) } td { (test_text(c)) } td { (j.flicker) }
                        td class=(j.verdict.name().replace(' ', "-")) { (verdict_text(&j.verdict)) }
                        td { (c.departures.join("; ")) }
                    }
                    "\n"
                }
            }
            "\n"
            @let rows = variants(&p.judged);
            @if !rows.is_empty() {
                h3 { "With and without each switched condition" }
                "\n"
                table {
                    tr { th { "claim" } th { "verdict" } th { "switched" } th { "verdict switched" } }
                    "\n"
                    @for [id, v, switched, vid, vv] in &rows {
                        tr { td { (id) } td { (v) } td { (switched) " (" (vid) ")" } td { (vv) } }
                        "\n"
                    }
                }
                "\n"
            }
            @for t in &p.tables {
                h3 { "Case " (t.case) " (mean [95% interval] over " (t.seeds) " seeds)" }
                "\n"
                table {
                    tr { th { "method" } @for c in &t.columns { th { (c) } } }
                    "\n"
                    @for (m, cells) in &t.rows {
                        tr { td { (m) } @for c in cells { td { (c) } } }
                        "\n"
                    }
                }
                "\n"
            }
        }
    }
    .into_string()
}

#[cfg(test)]
mod tests {
    //! The conclusion and rows from hand-made verdicts: what a reader relies on, read back from
    //! the text (each claim in its group, a failure's departure, an open claim's seeds, counts
    //! that add up, both methods of a comparison named in its row).

    use std::collections::BTreeMap;
    use std::path::PathBuf;

    use super::*;
    use crate::reproduce::effect::Effect;
    use crate::reproduce::judge::judge;
    use crate::reproduce::log_ratio::RatioExpectation;
    use crate::reproduce::verdict::num;
    use crate::suite::window::Window;

    fn claim(id: &str, comparison: Comparison, departures: &[&str]) -> Claim {
        Claim {
            id: id.into(),
            claim: format!("{id} holds"),
            source: "Table 1".into(),
            paper: "1.0".into(),
            case: None,
            statistic: None,
            comparison,
            smallest_effect: Effect::Relative(0.05),
            smallest_effect_from: "argued".into(),
            departures: departures.iter().map(|d| d.to_string()).collect(),
            variant_of: None,
            line: 0,
        }
    }

    fn below(a: &str, b: &str) -> Comparison {
        Comparison::Below { method: a.into(), than: b.into(), confidence: 0.95 }
    }

    fn hand_made(verdict: Verdict) -> Judged {
        Judged { flicker: "f".into(), verdict, values: vec![1.0, 2.0] }
    }

    /// The conclusion's groups by their label ("holds", "fails", "open", "not judged"), each
    /// as (claim id, what follows it up to the next id) in order.
    fn groups(text: &str) -> BTreeMap<&'static str, Vec<(String, String)>> {
        let labels = [
            ("holds", " Holds: "),
            ("fails", " Fails: "),
            ("open", " Open: "),
            ("not judged", " Not judged: "),
            ("not judged", "; not judged: "),
        ];
        let mut starts: Vec<(usize, &'static str, usize)> = labels
            .iter()
            .filter_map(|(name, l)| text.find(l).map(|i| (i, *name, i + l.len())))
            .collect();
        starts.sort();
        let mut out = BTreeMap::new();
        for (k, (_, name, from)) in starts.iter().enumerate() {
            let to = starts.get(k + 1).map_or(text.len(), |s| s.0);
            let section = &text[*from..to];
            // Ids are the odd pieces between backticks; each one's note is the piece after it.
            let pieces: Vec<&str> = section.split('`').collect();
            let entries: Vec<(String, String)> = (1..pieces.len())
                .step_by(2)
                .map(|i| (pieces[i].to_string(), pieces.get(i + 1).unwrap_or(&"").to_string()))
                .collect();
            out.insert(*name, entries);
        }
        out
    }

    /// The counts the conclusion opens with: (total, per verdict name).
    fn counts(text: &str) -> (usize, BTreeMap<String, usize>) {
        let (total, rest) = text.split_once(" claims: ").expect("opens with N claims:");
        let list = rest.split_once('.').expect("the counts end with a full stop").0;
        let per = list
            .split(", ")
            .map(|c| {
                let (n, name) = c.split_once(' ').unwrap();
                (name.to_string(), n.parse().unwrap())
            })
            .collect();
        (total.parse().unwrap(), per)
    }

    /// One group of `groups`, or a failure that shows the conclusion without it.
    fn group<'a>(
        g: &'a BTreeMap<&'static str, Vec<(String, String)>>,
        name: &str,
        text: &str,
    ) -> &'a Vec<(String, String)> {
        g.get(name).unwrap_or_else(|| panic!("no group '{name}' in: {text}"))
    }

    fn ids(group: Option<&Vec<(String, String)>>) -> Vec<&str> {
        group.map_or(vec![], |g| g.iter().map(|(id, _)| id.as_str()).collect())
    }

    /// One claim of each outcome (two kinds of open, two of not comparable): each lands in its
    /// group and in no other.
    #[test]
    fn each_claim_lands_in_its_group() {
        let declared = Comparison::NotComparable { methods: vec![], reason: "no metric".into() };
        let claims = [
            claim("holds_a", below("a", "b"), &[]),
            claim("fails_b", below("a", "b"), &["ours"]),
            claim("open_c", below("a", "b"), &["ours"]),
            claim("open_d", below("a", "b"), &[]),
            claim("unjudged_e", declared, &[]),
            claim("unjudged_f", below("a", "b"), &[]),
            claim("holds_g", below("a", "b"), &["ours"]),
        ];
        let verdicts = [
            Verdict::Reproduced,
            Verdict::NotReproduced,
            Verdict::Inconclusive { seeds: Some(12) },
            Verdict::Inconclusive { seeds: None },
            Verdict::NotComparable("declared".into()),
            Verdict::NotComparable("1 seed".into()),
            Verdict::Reproduced,
        ];
        let judged: Vec<(&Claim, Judged)> =
            claims.iter().zip(verdicts).map(|(c, v)| (c, hand_made(v))).collect();
        let text = conclusion(&judged);
        let g = groups(&text);
        assert_eq!(ids(g.get("holds")), ["holds_a", "holds_g"], "{text}");
        assert_eq!(ids(g.get("fails")), ["fails_b"], "{text}");
        assert_eq!(ids(g.get("open")), ["open_c", "open_d"], "{text}");
        assert_eq!(ids(g.get("not judged")), ["unjudged_e", "unjudged_f"], "{text}");
        // A declared claim is said to be unmeasured, one without data to have none.
        let notes: BTreeMap<&str, &str> = group(&g, "not judged", &text)
            .iter()
            .map(|(id, n)| (id.as_str(), n.as_str()))
            .collect();
        assert!(notes["unjudged_e"].contains("not measured by the lab"), "{text}");
        assert!(notes["unjudged_f"].contains("no data"), "{text}");

        // Only reproduced: no other group is written.
        let text = conclusion(&judged[..1]);
        assert_eq!(groups(&text).keys().copied().collect::<Vec<_>>(), ["holds"], "{text}");
        // Only open: under "Open", not under "Not judged".
        let text = conclusion(&judged[2..4]);
        assert_eq!(groups(&text).keys().copied().collect::<Vec<_>>(), ["open"], "{text}");
    }

    /// A failing claim names the departure its claims file lists first, or says none is listed.
    #[test]
    fn a_failing_claim_names_its_departure_or_says_none() {
        let claims = [
            claim("with", below("a", "b"), &["a profile of our own", "fewer bounces"]),
            claim("without", below("a", "b"), &[]),
            claim("passing", below("a", "b"), &["a passing claim's departure"]),
        ];
        let verdicts = [Verdict::NotReproduced, Verdict::NotReproduced, Verdict::Reproduced];
        let judged: Vec<(&Claim, Judged)> =
            claims.iter().zip(verdicts).map(|(c, v)| (c, hand_made(v))).collect();
        let text = conclusion(&judged);
        let fails: BTreeMap<String, String> =
            group(&groups(&text), "fails", &text).iter().cloned().collect();
        assert_eq!(fails.len(), 2, "{text}");
        assert!(fails["with"].contains("a profile of our own"), "{text}");
        assert!(!fails["with"].contains("fewer bounces"), "only the first: {text}");
        assert!(fails["without"].contains("names no departure"), "{text}");
        // A reproduced claim's departure is no reason for a failure.
        assert!(!text.contains("a passing claim's departure"), "{text}");
    }

    /// An open claim states about how many seeds would settle it, or why no number does.
    #[test]
    fn an_open_claim_states_its_seeds() {
        let claims = [claim("some", below("a", "b"), &[]), claim("none", below("a", "b"), &[])];
        let verdicts =
            [Verdict::Inconclusive { seeds: Some(37) }, Verdict::Inconclusive { seeds: None }];
        let judged: Vec<(&Claim, Judged)> =
            claims.iter().zip(verdicts).map(|(c, v)| (c, hand_made(v))).collect();
        let text = conclusion(&judged);
        let open: BTreeMap<String, String> =
            group(&groups(&text), "open", &text).iter().cloned().collect();
        assert!(open["some"].contains("37 seeds"), "{text}");
        assert!(open["none"].contains("sits on the margin"), "{text}");
        assert!(!open["none"].chars().any(|c| c.is_ascii_digit()), "no number of seeds: {text}");
    }

    /// The counts per verdict, in the vocabulary's order, add up to the claims and to each
    /// group's length, for mixes of outcomes (some absent).
    #[test]
    fn counts_add_up() {
        let all = [
            Verdict::Reproduced,
            Verdict::NotReproduced,
            Verdict::Inconclusive { seeds: Some(5) },
            Verdict::NotComparable("x".into()),
        ];
        // (reproduced, not reproduced, inconclusive, not comparable) per mix.
        for mix in [[3, 2, 1, 1], [0, 0, 4, 0], [1, 0, 0, 2], [0, 3, 0, 0], [2, 1, 3, 0]] {
            let claims: Vec<Claim> = mix
                .iter()
                .enumerate()
                .flat_map(|(k, &n)| (0..n).map(move |i| (k, i)))
                .map(|(k, i)| claim(&format!("c{k}_{i}"), below("a", "b"), &["d"]))
                .collect();
            let judged: Vec<(&Claim, Judged)> = claims
                .iter()
                .map(|c| {
                    let k: usize = c.id[1..2].parse().unwrap();
                    (c, hand_made(all[k].clone()))
                })
                .collect();
            let text = conclusion(&judged);
            let (total, per) = counts(&text);
            assert_eq!(total, judged.len(), "{text}");
            assert_eq!(per.keys().len(), VERDICTS.len(), "every verdict counted: {text}");
            assert_eq!(per.values().sum::<usize>(), total, "{text}");
            let g = groups(&text);
            let group = ["holds", "fails", "open", "not judged"];
            for (k, name) in VERDICTS.iter().enumerate() {
                assert_eq!(per[*name], mix[k], "{name}: {text}");
                assert_eq!(ids(g.get(group[k])).len(), mix[k], "{}: {text}", group[k]);
            }
            // In the vocabulary's order.
            let at: Vec<usize> =
                VERDICTS.iter().map(|v| text.find(&format!(" {v}")).unwrap()).collect();
            assert!(at.windows(2).all(|w| w[0] < w[1]), "{text}");
        }
    }

    /// Each comparison of two methods, judged on hand-made per-seed values, names both in its
    /// row (the test and what flicker measured), a relation each with its own mean.
    #[test]
    fn both_methods_are_named_in_rows() {
        let (a, b) = ([52.9, 52.8, 53.0], [51.5, 51.6, 51.5]);
        let per_seed = |m: &str, w: Option<&Window>| -> Result<Vec<f64>, String> {
            Ok(match (m, w) {
                ("ccv", None) => a.to_vec(),
                ("ccv", Some(_)) => b.to_vec(),
                ("as_pt", _) => b.to_vec(),
                _ => return Err(format!("no method {m}")),
            })
        };
        let two = |id: &str, c: Comparison| claim(id, c, &[]);
        let (m, t) = (String::from("ccv"), String::from("as_pt"));
        let claims = Claims {
            paper: "x".into(),
            title: "x".into(),
            cases: vec![],
            claims: vec![
                two("below", below("ccv", "as_pt")),
                two(
                    "not_above",
                    Comparison::NotAbove { method: m.clone(), than: t.clone(), confidence: 0.95 },
                ),
                two(
                    "ratio",
                    Comparison::Ratio {
                        method: m.clone(),
                        to: t.clone(),
                        value: 1.0,
                        confidence: 0.95,
                    },
                ),
                two(
                    "difference",
                    Comparison::Difference {
                        method: m.clone(),
                        to: t.clone(),
                        value: 1.0,
                        confidence: 0.95,
                    },
                ),
                two(
                    "log_below",
                    Comparison::LogRatio {
                        method: m.clone(),
                        to: t.clone(),
                        expect: RatioExpectation::Below(1.0),
                        confidence: 0.95,
                    },
                ),
                two(
                    "log_near",
                    Comparison::LogRatio {
                        method: m.clone(),
                        to: t.clone(),
                        expect: RatioExpectation::Near(1.0),
                        confidence: 0.95,
                    },
                ),
                two(
                    "rises",
                    Comparison::Rises {
                        method: m.clone(),
                        from: Window::Before { event: 0 },
                        confidence: 0.95,
                    },
                ),
            ],
            origin: PathBuf::from("claims/x.ron"),
            case_lines: BTreeMap::new(),
        };
        let judged: Vec<(&Claim, Judged)> = claims
            .claims
            .iter()
            .map(|c| (c, judge(&c.comparison, &c.smallest_effect, &per_seed)))
            .collect();
        let md = markdown("header", &[PaperResult { claims: &claims, judged, tables: vec![] }]);
        let mean = |v: &[f64]| v.iter().sum::<f64>() / v.len() as f64;
        for c in &claims.claims {
            let row = md
                .lines()
                .find(|l| l.starts_with(&format!("| {}: ", c.id)))
                .unwrap_or_else(|| panic!("no row for {}:\n{md}", c.id));
            let cells: Vec<&str> = row.split(" | ").collect();
            let (test, flicker) = (cells[3], cells[4]);
            // Rises compares one method over two windows; the others two methods.
            let (in_test, in_flicker) = match c.comparison {
                Comparison::Rises { .. } => (
                    vec!["ccv", "before_event_0"],
                    vec!["ccv over before_event_0", "the claim's window"],
                ),
                _ => (vec!["ccv", "as_pt"], vec!["ccv", "as_pt"]),
            };
            for n in in_test {
                assert!(test.contains(n), "{}: the test names {n}: {row}", c.id);
            }
            for n in in_flicker {
                assert!(flicker.contains(n), "{}: flicker's number names {n}: {row}", c.id);
            }
            // A relation gives each method its own mean, in the claim's order.
            if matches!(c.comparison, Comparison::Below { .. } | Comparison::NotAbove { .. }) {
                let each = format!("ccv {} vs as_pt {}", num(mean(&a)), num(mean(&b)));
                assert!(flicker.contains(&each), "{}: {each} in {row}", c.id);
            }
        }
    }
}
