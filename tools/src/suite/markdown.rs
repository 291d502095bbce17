//! The suite's Markdown summary: one row per (case, method, gate), failures first.

use super::gate::{GateResult, Verdict};

pub fn summary(
    suite: &str,
    adapter: &str,
    baseline: Option<(&str, &str)>,
    stand_in: Option<&str>,
    results: &[GateResult],
) -> String {
    let failed = results.iter().filter(|r| !r.passed()).count();
    let mut out = format!(
        "# Suite {suite}: {}\n\n",
        if failed == 0 {
            "passed".to_string()
        } else {
            format!("{failed} of {} checks failed", results.len())
        }
    );
    out.push_str(&format!("Adapter: {adapter}\n\n"));
    match (baseline, stand_in) {
        (Some(_), Some(note)) => out.push_str(&format!("Baseline: {note}\n\n")),
        (Some((commit, date)), None) => {
            out.push_str(&format!("Baseline: commit {commit}, blessed {date}\n\n"))
        }
        (None, _) => out.push_str("Baseline: none for this adapter (absolute gates only)\n\n"),
    }
    out.push_str("| result | case | method | gate | new mean | baseline mean | p | detail |\n|---|---|---|---|---:|---:|---:|---|\n");
    let mut rows: Vec<&GateResult> = results.iter().collect();
    rows.sort_by_key(|r| r.passed());
    for r in rows {
        let verdict = match &r.verdict {
            Verdict::Pass => "pass",
            Verdict::Fail => "**FAIL**",
            Verdict::Error(_) => "**ERROR**",
        };
        let mean = |s: Option<super::welch::Sample>| {
            s.map(|s| format!("{:.5}", s.mean)).unwrap_or_default()
        };
        out.push_str(&format!(
            "| {verdict} | {} | {} | {} | {} | {} | {} | {} |\n",
            r.case,
            r.method,
            r.gate,
            mean(r.new),
            mean(r.baseline),
            r.p_value.map(|p| format!("{p:.4}")).unwrap_or_default(),
            r.detail.replace('|', "\\|")
        ));
    }
    out
}
