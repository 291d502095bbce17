//! reproduce.md and reproduce.html: one row per claim, the paper's number beside flicker's with
//! its interval, the verdict and the known departures.

use super::claims::{Claim, Claims};
use super::judge::{Judged, Verdict};
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
    match v {
        Verdict::NotComparable(why) => format!("not comparable: {why}"),
        v => v.name().to_string(),
    }
}

fn test_text(c: &Claim) -> String {
    let stat = c.statistic.as_ref().map(|s| s.describe()).unwrap_or_default();
    let case = c.case.as_deref().unwrap_or("-");
    format!("{} on {case}, {stat}", c.comparison.describe())
}

/// The Markdown report; `header` says how it was made (command, scale, seeds, commit).
pub fn markdown(header: &str, papers: &[PaperResult]) -> String {
    let mut md = format!("# What the papers claim, and what we measure\n\n{header}\n");
    for p in papers {
        md.push_str(&format!("\n## {} ({})\n\n", p.claims.title, p.claims.paper));
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
                cell(&format!("{} (tolerance: {})", test_text(c), c.tolerance_from)),
                cell(&j.flicker),
                cell(&verdict_text(&j.verdict)),
                cell(&c.departures.join("; ")),
            ));
        }
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
        "<!doctype html><meta charset=\"utf-8\"><title>flicker reproduce</title>\n<style>body{font-family:sans-serif;margin:2em}table{border-collapse:collapse}td,th{border:1px solid #ccc;padding:4px;vertical-align:top;font-size:90%}.reproduced{background:#d9f2d9}.not-reproduced{background:#f6d5d5}.not-comparable{background:#eee}</style>\n",
    );
    h.push_str(&format!(
        "<h1>What the papers claim, and what we measure</h1>\n<p>{}</p>\n",
        escape(header)
    ));
    for p in papers {
        h.push_str(&format!(
            "<h2>{} ({})</h2>\n<table><tr><th>claim</th><th>where</th><th>paper</th><th>test</th><th>flicker (95% interval)</th><th>verdict</th><th>departures</th></tr>\n",
            escape(&p.claims.title),
            escape(&p.claims.paper)
        ));
        for (c, j) in &p.judged {
            let class = j.verdict.name().replace(' ', "-");
            h.push_str(&format!(
                "<tr><td><b>{}</b>: {}</td><td>{}</td><td>{}</td><td>{} (tolerance: {})</td><td>{}</td><td class=\"{class}\">{}</td><td>{}</td></tr>\n",
                escape(&c.id),
                escape(&c.claim),
                escape(&c.source),
                escape(&c.paper),
                escape(&test_text(c)),
                escape(&c.tolerance_from),
                escape(&j.flicker),
                escape(&verdict_text(&j.verdict)),
                escape(&c.departures.join("; ")),
            ));
        }
        h.push_str("</table>\n");
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
