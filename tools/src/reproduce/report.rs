//! reproduce.md and reproduce.html: per paper a conclusion built from its claims (counts per
//! verdict, what holds, what fails and the departure its claims file names first, what is
//! open), then one row per claim: the paper's number beside flicker's (both methods named)
//! with its interval, the verdict and the known departures.

use maud::{PreEscaped, html};

use super::claims::{Claim, Claims, Comparison};
use super::judge::{Judged, VERDICTS, Verdict};
use super::table::{self, CaseTable};

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
