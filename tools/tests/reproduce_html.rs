//! reproduce.html: every name a claims file, a case or a method sets stands escaped in the page.

use tools::reproduce::report::{PaperResult, html};
use tools::reproduce::run::load_claims;
use tools::reproduce::table::CaseTable;
use tools::reproduce::{Judged, Verdict};
/// A name as a claims file or a case may set it: markup and quotes.
const HOSTILE: &str = "<img src=x onerror=alert(1)>\"'&";
const ESCAPED: &str = "&lt;img src=x onerror=alert(1)&gt;&quot;'&amp;";

#[test]
fn the_page_escapes_every_name_of_claims_cases_and_methods() {
    let dir = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../claims");
    let mut claims = load_claims(&dir, "stable-sample-caching").unwrap().remove(0);
    let mut claim = claims.claims[0].clone();
    (claims.title, claims.paper) = (HOSTILE.into(), HOSTILE.into());
    (claim.id, claim.claim, claim.source, claim.paper) =
        (HOSTILE.into(), HOSTILE.into(), HOSTILE.into(), HOSTILE.into());
    claim.departures = vec![HOSTILE.into()];
    let judged = Judged {
        flicker: HOSTILE.into(),
        verdict: Verdict::NotComparable(HOSTILE.into()),
        values: Vec::new(),
    };
    let tables = vec![CaseTable {
        case: HOSTILE.into(),
        seeds: 3,
        columns: vec![HOSTILE.into()],
        rows: vec![(HOSTILE.into(), vec![HOSTILE.into()])],
    }];
    let page = PaperResult { claims: &claims, judged: vec![(&claim, judged)], tables };
    let h = html(HOSTILE, &[page]);
    assert!(!h.contains("<img") && !h.contains(HOSTILE), "unescaped name: {h}");
    let e = ESCAPED;
    for part in [
        format!("<p>{e}</p>"),
        format!("<h2>{e} ({e})</h2>"),
        format!("<tr><td><b>{e}</b>: {e}</td><td>{e}</td><td>{e}</td>"),
        format!(
            "<td>{e}</td><td class=\"not-comparable\">not comparable: {e}</td><td>{e}</td></tr>"
        ),
        format!("<h3>Case {e} (mean [95% interval] over 3 seeds)</h3>"),
        format!("<tr><th>method</th><th>{e}</th></tr>"),
        format!("<tr><td>{e}</td><td>{e}</td></tr>"),
    ] {
        assert!(h.contains(&part), "{part} is not in the page:\n{h}");
    }
}
