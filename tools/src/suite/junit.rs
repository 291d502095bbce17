//! JUnit XML, what CI systems read: one `<testsuite>` per case, one `<testcase>` per (method,
//! gate), `<failure>` for a failed gate and `<error>` for one that could not be judged.

use super::gate::{GateResult, Verdict};

fn escape(s: &str) -> String {
    s.replace('&', "&amp;")
        .replace('<', "&lt;")
        .replace('>', "&gt;")
        .replace('"', "&quot;")
        .replace('\'', "&apos;")
}

pub fn report(suite: &str, results: &[GateResult]) -> String {
    let mut cases: Vec<&str> = results.iter().map(|r| r.case.as_str()).collect();
    cases.dedup();
    let count =
        |v: &[&GateResult], f: fn(&Verdict) -> bool| v.iter().filter(|r| f(&r.verdict)).count();
    let fail = |v: &Verdict| *v == Verdict::Fail;
    let error = |v: &Verdict| matches!(v, Verdict::Error(_));
    let all: Vec<&GateResult> = results.iter().collect();
    let mut out = format!(
        "<?xml version=\"1.0\" encoding=\"UTF-8\"?>\n<testsuites name=\"{}\" tests=\"{}\" failures=\"{}\" errors=\"{}\">\n",
        escape(suite),
        all.len(),
        count(&all, fail),
        count(&all, error)
    );
    for case in cases {
        let rows: Vec<&GateResult> = results.iter().filter(|r| r.case == case).collect();
        out.push_str(&format!(
            "  <testsuite name=\"{}.{}\" tests=\"{}\" failures=\"{}\" errors=\"{}\">\n",
            escape(suite),
            escape(case),
            rows.len(),
            count(&rows, fail),
            count(&rows, error)
        ));
        for r in rows {
            let head = format!(
                "    <testcase classname=\"{}.{}.{}\" name=\"{}\"",
                escape(suite),
                escape(case),
                escape(&r.method),
                escape(&r.gate)
            );
            match &r.verdict {
                Verdict::Pass => out.push_str(&format!(
                    "{head}>\n      <system-out>{}</system-out>\n    </testcase>\n",
                    escape(&r.detail)
                )),
                Verdict::Fail => out.push_str(&format!(
                    "{head}>\n      <failure message=\"{}\"/>\n    </testcase>\n",
                    escape(&r.detail)
                )),
                Verdict::Error(e) => out.push_str(&format!(
                    "{head}>\n      <error message=\"{}\"/>\n    </testcase>\n",
                    escape(e)
                )),
            }
        }
        out.push_str("  </testsuite>\n");
    }
    out.push_str("</testsuites>\n");
    out
}
