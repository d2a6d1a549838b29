//! Tests of the runner: every tolerance kind through a case, and the
//! expected-failure ratchet.

use super::*;

fn all_kinds() -> Result<Vec<Check>, Error> {
    Ok(vec![
        Check::new("within-pass", 1.0, 1.004, Tolerance::Within(0.005)),
        Check::new("within-fail", 1.0, 1.006, Tolerance::Within(0.005)),
        Check::new("at-most-pass", 0.18, 0.17, Tolerance::AtMost(0.005)),
        Check::new("at-most-fail", 0.18, 0.19, Tolerance::AtMost(0.005)),
        Check::new("at-least-pass", 100.0, 120.0, Tolerance::AtLeast(0.0)),
        Check::new("at-least-fail", 100.0, 90.0, Tolerance::AtLeast(0.0)),
        Check::new("relative-pass", 50.0, 50.4, Tolerance::Relative(0.01)),
        Check::new("relative-fail", 50.0, 51.0, Tolerance::Relative(0.01)),
        Check::new("nan-fail", 1.0, f64::NAN, Tolerance::Within(1e9)),
    ])
}

fn one_pass() -> Result<Vec<Check>, Error> {
    Ok(vec![Check::new("m", 2.0, 2.0, Tolerance::Within(0.0))])
}

fn one_fail() -> Result<Vec<Check>, Error> {
    Ok(vec![Check::new("m", 2.0, 3.0, Tolerance::Within(0.5))])
}

fn broken() -> Result<Vec<Check>, Error> {
    Err(Error::computation("singular matrix"))
}

const KINDS: Case = Case {
    name: "test/kinds",
    description: "every tolerance kind",
    fast: true,
    heavy: false,
    run: all_kinds,
};

fn case(name: &'static str, fast: bool, run: fn() -> Result<Vec<Check>, Error>) -> Case {
    Case {
        name,
        description: "test",
        fast,
        heavy: false,
        run,
    }
}

fn status_of(report: &Report, metric: &str) -> Status {
    report
        .rows
        .iter()
        .find(|r| r.metric == metric)
        .map(|r| r.status)
        .expect("metric present")
}

#[test]
fn each_tolerance_kind_passes_and_fails() {
    let report = run(&[KINDS], &[], &RunOptions::default());
    for kind in ["within", "at-most", "at-least", "relative"] {
        assert_eq!(
            status_of(&report, &format!("{kind}-pass")),
            Status::Pass,
            "{kind}"
        );
        assert_eq!(
            status_of(&report, &format!("{kind}-fail")),
            Status::Fail,
            "{kind}"
        );
    }
    assert_eq!(status_of(&report, "nan-fail"), Status::Fail);
    assert_eq!(
        report.verdict(),
        Err(Error::Failed {
            unexpected: 5,
            errors: 0,
            fixed: 0,
            stale: 0
        })
    );
}

#[test]
fn zero_cases_is_a_failure() {
    let report = run(&[], &[], &RunOptions::default());
    assert_eq!(report.verdict(), Err(Error::NoCaseRan));
    assert_eq!(Error::NoCaseRan.to_string(), "no case ran");
    // a filter that matches nothing is the same failure
    let report = run(
        &[KINDS],
        &[],
        &RunOptions {
            filter: Some("no-such-case".into()),
            fast_only: false,
            heavy: false,
        },
    );
    assert_eq!(report.verdict(), Err(Error::NoCaseRan));
}

#[test]
fn unexpected_failure_fails_the_run() {
    let report = run(
        &[case("c/fail", true, one_fail)],
        &[],
        &RunOptions::default(),
    );
    assert_eq!(status_of(&report, "m"), Status::Fail);
    assert!(report.verdict().is_err());
}

#[test]
fn listed_failure_is_tolerated() {
    let listed = [ExpectedFailure {
        case: "c/fail",
        metric: "m",
        reason: "source prints 2, recomputes to 3",
    }];
    let report = run(
        &[case("c/fail", true, one_fail)],
        &listed,
        &RunOptions::default(),
    );
    assert_eq!(status_of(&report, "m"), Status::ExpectedFailure);
    assert_eq!(report.rows[0].note, "source prints 2, recomputes to 3");
    let summary = report.verdict().expect("listed failure passes the run");
    assert_eq!(summary.expected_failures, 1);
}

#[test]
fn listed_failure_that_now_passes_fails_the_run() {
    let listed = [ExpectedFailure {
        case: "c/pass",
        metric: "m",
        reason: "was broken",
    }];
    let report = run(
        &[case("c/pass", true, one_pass)],
        &listed,
        &RunOptions::default(),
    );
    assert_eq!(status_of(&report, "m"), Status::UnexpectedPass);
    assert_eq!(
        report.verdict(),
        Err(Error::Failed {
            unexpected: 0,
            errors: 0,
            fixed: 1,
            stale: 0
        })
    );
}

#[test]
fn stale_entry_fails_only_when_its_case_ran() {
    let listed = [ExpectedFailure {
        case: "c/pass",
        metric: "gone",
        reason: "metric was renamed",
    }];
    let report = run(
        &[case("c/pass", true, one_pass)],
        &listed,
        &RunOptions::default(),
    );
    assert_eq!(status_of(&report, "gone"), Status::Stale);
    assert!(report.verdict().is_err());
    // filtered out: the entry is not judged
    let report = run(
        &[
            case("c/pass", true, one_pass),
            case("d/other", true, one_pass),
        ],
        &listed,
        &RunOptions {
            filter: Some("d/".into()),
            fast_only: false,
            heavy: false,
        },
    );
    assert!(report.verdict().is_ok());
}

#[test]
fn case_error_fails_the_run() {
    let report = run(
        &[case("c/broken", true, broken)],
        &[],
        &RunOptions::default(),
    );
    assert_eq!(report.rows[0].status, Status::Error);
    assert!(report.rows[0].note.contains("singular matrix"));
    assert!(report.verdict().is_err());
}

#[test]
fn fast_only_skips_slow_cases() {
    let cases = [
        case("a/fast", true, one_pass),
        case("a/slow", false, one_fail),
    ];
    let report = run(
        &cases,
        &[],
        &RunOptions {
            filter: None,
            fast_only: true,
            heavy: false,
        },
    );
    assert_eq!(report.cases_run, vec!["a/fast".to_owned()]);
    assert!(report.verdict().is_ok());
}

#[test]
fn heavy_cases_run_only_when_asked() {
    let mut big = case("a/heavy", false, one_pass);
    big.heavy = true;
    let cases = [case("a/slow", false, one_pass), big];
    let ran = |heavy: bool, filter: Option<&str>| {
        run(
            &cases,
            &[],
            &RunOptions {
                filter: filter.map(str::to_owned),
                fast_only: false,
                heavy,
            },
        )
        .cases_run
    };
    assert_eq!(ran(false, None), vec!["a/slow".to_owned()]);
    assert_eq!(ran(true, None).len(), 2);
    // a filter alone does not run it either
    assert_eq!(ran(false, Some("a/heavy")), Vec::<String>::new());
    assert_eq!(ran(true, Some("a/heavy")), vec!["a/heavy".to_owned()]);
}

#[test]
fn renders_markdown_and_csv() {
    let report = run(
        &[case("c/pass", true, one_pass)],
        &[],
        &RunOptions::default(),
    );
    let md = report.to_markdown();
    assert!(
        md.contains("| c/pass | m | 2 | 2 | within ±0 | pass |  |"),
        "{md}"
    );
    assert!(md.contains("1 cases, 1 checks: 1 passed"), "{md}");
    let mut csv = Vec::new();
    report.write_csv(&mut csv).expect("write to a Vec");
    let csv = String::from_utf8(csv).expect("utf-8");
    assert_eq!(
        csv,
        "case,metric,reference,ours,tolerance,status,note\nc/pass,m,2,2,within ±0,pass,\n"
    );
}

#[test]
fn csv_quotes_commas_and_quotes() {
    assert_eq!(csv_field("a,b"), "\"a,b\"");
    assert_eq!(csv_field("say \"x\""), "\"say \"\"x\"\"\"");
    assert_eq!(csv_field("plain"), "plain");
}
