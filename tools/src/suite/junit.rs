//! JUnit XML, what CI systems read (written by `quick-junit`): one `<testsuite>` per case, one
//! `<testcase>` per (method, gate), `<failure>` for a failed gate and `<error>` for one that could
//! not be judged.

use quick_junit::{NonSuccessKind, Report, TestCase, TestCaseStatus, TestSuite};

use super::gate::{GateResult, Verdict};

pub fn report(suite: &str, results: &[GateResult]) -> String {
    let mut cases: Vec<&str> = results.iter().map(|r| r.case.as_str()).collect();
    cases.dedup();
    let mut report = Report::new(suite);
    for case in cases {
        let mut test_suite = TestSuite::new(format!("{suite}.{case}"));
        for r in results.iter().filter(|r| r.case == case) {
            let failed = |kind, message: &str| {
                let mut status = TestCaseStatus::non_success(kind);
                status.set_message(message);
                status
            };
            let status = match &r.verdict {
                Verdict::Pass => TestCaseStatus::success(),
                Verdict::Fail => failed(NonSuccessKind::Failure, &r.detail),
                Verdict::Error(e) => failed(NonSuccessKind::Error, e),
            };
            let mut test_case = TestCase::new(r.gate.as_str(), status);
            test_case.set_classname(format!("{suite}.{case}.{}", r.method));
            if r.verdict == Verdict::Pass {
                test_case.set_system_out(r.detail.as_str());
            }
            test_suite.add_test_case(test_case);
        }
        report.add_test_suite(test_suite);
    }
    report.to_string().expect("a report in memory serializes")
}

#[cfg(test)]
mod tests {
    use super::*;

    fn result(case: &str, gate: &str, verdict: Verdict, detail: &str) -> GateResult {
        GateResult {
            case: case.into(),
            method: "m<1>".into(),
            gate: gate.into(),
            new: None,
            baseline: None,
            p_value: None,
            verdict,
            detail: detail.into(),
        }
    }

    /// Read back by quick-junit's own parser: counts per level, and names and messages with
    /// XML's special characters intact.
    #[test]
    fn counts_and_escaped_text_read_back() {
        let results = [
            result("a&b", "flip \"mean\"", Verdict::Pass, "0.1 < 0.2"),
            result("a&b", "smape", Verdict::Fail, "0.3 > 0.2 & p = 0.01"),
            result("c", "jod", Verdict::Error("no baseline for 'c'".into()), ""),
        ];
        let xml = report("s", &results);
        let back = Report::deserialize_from_str(&xml).unwrap();
        assert_eq!((back.tests, back.failures, back.errors), (3, 1, 1));
        let suites: Vec<(&str, usize, usize, usize)> = back
            .test_suites
            .iter()
            .map(|s| (s.name.as_str(), s.tests, s.failures, s.errors))
            .collect();
        assert_eq!(suites, [("s.a&b", 2, 1, 0), ("s.c", 1, 0, 1)]);
        let pass = &back.test_suites[0].test_cases[0];
        assert_eq!(pass.name.as_str(), "flip \"mean\"");
        assert_eq!(pass.classname.as_ref().unwrap().as_str(), "s.a&b.m<1>");
        assert_eq!(pass.system_out.as_ref().unwrap().as_str(), "0.1 < 0.2");
        let message = |c: &TestCase| match &c.status {
            TestCaseStatus::NonSuccess { kind, message, .. } => {
                (*kind, message.as_ref().unwrap().as_str().to_string())
            }
            _ => panic!("expected a failure or an error"),
        };
        assert_eq!(
            message(&back.test_suites[0].test_cases[1]),
            (NonSuccessKind::Failure, "0.3 > 0.2 & p = 0.01".to_string())
        );
        assert_eq!(
            message(&back.test_suites[1].test_cases[0]),
            (NonSuccessKind::Error, "no baseline for 'c'".to_string())
        );
    }
}
