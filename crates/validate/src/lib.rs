//! Reference validation for grainforge: every reproduction of a published
//! table or real-data result is a registered [`Case`] whose [`Check`]s compare
//! our number with the reference under an explicit [`Tolerance`].
//!
//! The runner (modelled on georust/geo's `jts-test-runner`) renders a result
//! table (case, metric, reference, ours, tolerance, status) as markdown or
//! CSV, and its verdict fails on an unexpected failure, on a case error, on
//! zero cases run, and when an entry of the expected-failure list (each with
//! a written reason) starts passing or goes stale — a ratchet that only lets
//! the list shrink.
//!
//! Reference data come from the embedded `fixtures/` tree ([`fixtures`]);
//! this crate touches no file at run time. `cargo xtask validate` runs every
//! case; a `#[test]` runs the fast subset so `cargo test` covers it.
//!
//! ```
//! use validate::{registry, expected_failures, run, RunOptions};
//!
//! let options = RunOptions {
//!     filter: Some("fixtures/gsc2018-table4".into()),
//!     fast_only: true,
//!     heavy: false,
//! };
//! let report = run(&registry(), &expected_failures(), &options);
//! let summary = report.verdict().expect("table 4 averages are consistent");
//! assert!(summary.passed > 0);
//! println!("{}", report.to_markdown());
//! ```
//!
//! Layer 3: may depend on every library crate (see `docs/architecture.md`).

mod error;
pub mod fixtures;
pub mod grains;
mod runner;
mod tolerance;

pub mod cases;

pub use cases::{expected_failures, registry};
pub use error::Error;
pub use runner::{Case, Check, ExpectedFailure, Report, Row, RunOptions, Status, Summary, run};
pub use tolerance::Tolerance;

#[cfg(test)]
mod tests {
    use super::*;

    /// The fast subset of the whole registry passes: this is how
    /// `cargo test` covers `cargo xtask validate`.
    #[test]
    fn fast_subset_passes() {
        let report = run(
            &registry(),
            &expected_failures(),
            &RunOptions {
                filter: None,
                fast_only: true,
                heavy: false,
            },
        );
        if let Err(err) = report.verdict() {
            let failing: Vec<String> = report
                .rows
                .iter()
                .filter(|r| r.status.is_failure())
                .map(|r| {
                    format!(
                        "{} / {}: ref {} ours {} ({}) {} {}",
                        r.case,
                        r.metric,
                        r.reference,
                        r.ours,
                        r.tolerance,
                        r.status.label(),
                        r.note
                    )
                })
                .collect();
            panic!("{err}\n{}", failing.join("\n"));
        }
    }

    #[test]
    fn case_names_are_unique_and_expected_failures_name_real_cases() {
        let cases = registry();
        let mut names: Vec<&str> = cases.iter().map(|c| c.name).collect();
        names.sort_unstable();
        let before = names.len();
        names.dedup();
        assert_eq!(before, names.len(), "duplicate case names");
        for e in expected_failures() {
            assert!(
                names.contains(&e.case),
                "expected failure names unknown case {}",
                e.case
            );
            assert!(
                !e.reason.trim().is_empty(),
                "expected failure without a reason: {e:?}"
            );
        }
    }
}
