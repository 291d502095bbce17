//! reproduce.md and reproduce.html: per paper a conclusion built from its claims (counts per
//! verdict, what holds, what fails and the departure its claims file names first, what is
//! open), then one row per claim: the paper's number beside flicker's (both methods named)
//! with its interval, the verdict and the known departures.

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

fn escape(s: &str) -> String {
    s.replace('&', "&amp;").replace('<', "&lt;").replace('>', "&gt;")
}

/// The same table as a standalone page, verdicts coloured.
pub fn html(header: &str, papers: &[PaperResult]) -> String {
    let mut h = String::from(
        "<!doctype html><meta charset=\"utf-8\"><title>flicker reproduce</title>\n<style>body{font-family:sans-serif;margin:2em}table{border-collapse:collapse}td,th{border:1px solid #ccc;padding:4px;vertical-align:top;font-size:90%}.reproduced{background:#d9f2d9}.not-reproduced{background:#f6d5d5}.inconclusive{background:#fdf3cf}.not-comparable{background:#eee}</style>\n",
    );
    h.push_str(&format!(
        "<h1>What the papers claim, and what we measure</h1>\n<p>{}</p>\n",
        escape(header)
    ));
    for p in papers {
        h.push_str(&format!(
            "<h2>{} ({})</h2>\n<p>{}</p>\n<table><tr><th>claim</th><th>where</th><th>paper</th><th>test</th><th>flicker (95% interval)</th><th>verdict</th><th>departures</th></tr>\n",
            escape(&p.claims.title),
            escape(&p.claims.paper),
            escape(&conclusion(&p.judged).replace('`', ""))
        ));
        for (c, j) in &p.judged {
            let class = j.verdict.name().replace(' ', "-");
            h.push_str(&format!(
                "<tr><td><b>{}</b>: {}</td><td>{}</td><td>{}</td><td>{}</td><td>{}</td><td class=\"{class}\">{}</td><td>{}</td></tr>\n",
                escape(&c.id),
                escape(&c.claim),
                escape(&c.source),
                escape(&c.paper),
                escape(&test_text(c)),
                escape(&j.flicker),
                escape(&verdict_text(&j.verdict)),
                escape(&c.departures.join("; ")),
            ));
        }
        h.push_str("</table>\n");
        let rows = variants(&p.judged);
        if !rows.is_empty() {
            h.push_str("<h3>With and without each switched condition</h3>\n<table><tr><th>claim</th><th>verdict</th><th>switched</th><th>verdict switched</th></tr>\n");
            for [id, v, switched, vid, vv] in rows {
                h.push_str(&format!(
                    "<tr><td>{}</td><td>{}</td><td>{} ({})</td><td>{}</td></tr>\n",
                    escape(&id),
                    escape(&v),
                    escape(&switched),
                    escape(&vid),
                    escape(&vv)
                ));
            }
            h.push_str("</table>\n");
        }
        for t in &p.tables {
            h.push_str(&format!(
                "<h3>Case {} (mean [95% interval] over {} seeds)</h3>\n<table><tr><th>method</th>",
                escape(&t.case),
                t.seeds
            ));
            for c in &t.columns {
                h.push_str(&format!("<th>{}</th>", escape(c)));
            }
            h.push_str("</tr>\n");
            for (m, cells) in &t.rows {
                h.push_str(&format!("<tr><td>{}</td>", escape(m)));
                for c in cells {
                    h.push_str(&format!("<td>{}</td>", escape(c)));
                }
                h.push_str("</tr>\n");
            }
            h.push_str("</table>\n");
        }
    }
    h
}
