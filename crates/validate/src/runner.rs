//! The case registry types, the runner and its expected-failure ratchet
//! (modelled on georust/geo's `jts-test-runner`).

use std::fmt::Write as _;
use std::io;

use crate::{Error, Tolerance};

/// One compared quantity of a case: a metric, the reference value, ours and
/// the tolerance that judges them.
#[derive(Debug, Clone, PartialEq)]
pub struct Check {
    /// Metric name, unique within its case (e.g. `"volume"`, `"trial_4"`).
    pub metric: String,
    /// The reference value (from `fixtures/reference/` or a closed form).
    pub reference: f64,
    /// The value we computed.
    pub ours: f64,
    /// How `ours` is judged against `reference`.
    pub tolerance: Tolerance,
}

impl Check {
    /// Builds a check.
    pub fn new(metric: impl Into<String>, reference: f64, ours: f64, tolerance: Tolerance) -> Self {
        Self {
            metric: metric.into(),
            reference,
            ours,
            tolerance,
        }
    }

    /// Whether the check passes.
    #[must_use]
    pub fn passes(&self) -> bool {
        self.tolerance.holds(self.reference, self.ours)
    }
}

/// A registered validation case.
#[derive(Debug, Clone, Copy)]
pub struct Case {
    /// Unique name, `group/what` (e.g. `fixtures/gsc2018-table4-average`).
    pub name: &'static str,
    /// One line saying what the case reproduces and from where.
    pub description: &'static str,
    /// Whether the case belongs to the fast subset that `cargo test` runs.
    pub fast: bool,
    /// Too long for every run (tens of minutes on 2 cores): runs only with
    /// [`RunOptions::heavy`] (`cargo xtask validate --heavy`).
    pub heavy: bool,
    /// Computes the case's checks.
    pub run: fn() -> Result<Vec<Check>, Error>,
}

/// A (case, metric) pair that is known to fail, with the reason.
///
/// The ratchet: a listed pair that fails is fine, a listed pair that passes
/// fails the run (the list must shrink when a fix lands), and a listed pair
/// whose case ran without producing that metric fails the run as stale.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct ExpectedFailure {
    /// Case name.
    pub case: &'static str,
    /// Metric name within the case.
    pub metric: &'static str,
    /// Why it fails: a source inconsistency (cite `NOTES.md`) or a known
    /// limitation of ours.
    pub reason: &'static str,
}

/// Outcome of one row of the result table.
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord)]
pub enum Status {
    /// Within tolerance and not listed.
    Pass,
    /// Out of tolerance and listed as an expected failure.
    ExpectedFailure,
    /// Out of tolerance and not listed: fails the run.
    Fail,
    /// Listed as an expected failure but passes: fails the run.
    UnexpectedPass,
    /// Listed, but the case ran without producing the metric: fails the run.
    Stale,
    /// The case could not compute: fails the run.
    Error,
}

impl Status {
    /// Short label used in the tables.
    #[must_use]
    pub fn label(self) -> &'static str {
        match self {
            Self::Pass => "pass",
            Self::ExpectedFailure => "xfail",
            Self::Fail => "FAIL",
            Self::UnexpectedPass => "XPASS",
            Self::Stale => "STALE",
            Self::Error => "ERROR",
        }
    }

    /// Whether this status fails the run.
    #[must_use]
    pub fn is_failure(self) -> bool {
        matches!(
            self,
            Self::Fail | Self::UnexpectedPass | Self::Stale | Self::Error
        )
    }
}

/// One row of the result table.
#[derive(Debug, Clone, PartialEq)]
pub struct Row {
    /// Case name.
    pub case: String,
    /// Metric name (`"-"` for a case error).
    pub metric: String,
    /// Reference value (NaN when not applicable).
    pub reference: f64,
    /// Our value (NaN when not applicable).
    pub ours: f64,
    /// Rendered tolerance.
    pub tolerance: String,
    /// Outcome.
    pub status: Status,
    /// Expected-failure reason or error message; empty otherwise.
    pub note: String,
}

/// What to run.
#[derive(Debug, Clone, Default)]
pub struct RunOptions {
    /// Only cases whose name contains this substring (or one of several,
    /// comma-separated).
    pub filter: Option<String>,
    /// Only the fast subset.
    pub fast_only: bool,
    /// Also the heavy cases ([`Case::heavy`]).
    pub heavy: bool,
}

/// The result table of a run.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct Report {
    /// Names of the cases that ran, in order.
    pub cases_run: Vec<String>,
    /// All rows, in case order then metric order.
    pub rows: Vec<Row>,
}

/// Runs `cases` (after filtering) and judges every check against the
/// expected-failure list.
#[must_use]
pub fn run(cases: &[Case], expected: &[ExpectedFailure], options: &RunOptions) -> Report {
    let mut report = Report::default();
    for case in cases {
        if (options.fast_only && !case.fast) || (case.heavy && !options.heavy) {
            continue;
        }
        if let Some(filter) = &options.filter
            && !filter.split(',').any(|f| case.name.contains(f))
        {
            continue;
        }
        report.cases_run.push(case.name.to_owned());
        let listed: Vec<&ExpectedFailure> =
            expected.iter().filter(|e| e.case == case.name).collect();
        match (case.run)() {
            Err(err) => report.rows.push(Row {
                case: case.name.to_owned(),
                metric: "-".to_owned(),
                reference: f64::NAN,
                ours: f64::NAN,
                tolerance: String::new(),
                status: Status::Error,
                note: err.to_string(),
            }),
            Ok(checks) => {
                for check in &checks {
                    let entry = listed.iter().find(|e| e.metric == check.metric);
                    let status = match (check.passes(), entry) {
                        (true, None) => Status::Pass,
                        (true, Some(_)) => Status::UnexpectedPass,
                        (false, Some(_)) => Status::ExpectedFailure,
                        (false, None) => Status::Fail,
                    };
                    report.rows.push(Row {
                        case: case.name.to_owned(),
                        metric: check.metric.clone(),
                        reference: check.reference,
                        ours: check.ours,
                        tolerance: check.tolerance.to_string(),
                        status,
                        note: entry.map(|e| e.reason.to_owned()).unwrap_or_default(),
                    });
                }
                for entry in listed {
                    if !checks.iter().any(|c| c.metric == entry.metric) {
                        report.rows.push(Row {
                            case: case.name.to_owned(),
                            metric: entry.metric.to_owned(),
                            reference: f64::NAN,
                            ours: f64::NAN,
                            tolerance: String::new(),
                            status: Status::Stale,
                            note: "listed as an expected failure, but the case produced no such metric"
                                .to_owned(),
                        });
                    }
                }
            }
        }
    }
    report
}

/// Counts of a run by status.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct Summary {
    /// Cases that ran.
    pub cases: usize,
    /// Passing checks.
    pub passed: usize,
    /// Listed failures that failed.
    pub expected_failures: usize,
    /// Unlisted failures.
    pub failed: usize,
    /// Listed failures that passed.
    pub unexpected_passes: usize,
    /// Stale list entries.
    pub stale: usize,
    /// Case errors.
    pub errors: usize,
}

impl Report {
    /// Counts the rows by status.
    #[must_use]
    pub fn summary(&self) -> Summary {
        let mut s = Summary {
            cases: self.cases_run.len(),
            ..Summary::default()
        };
        for row in &self.rows {
            match row.status {
                Status::Pass => s.passed += 1,
                Status::ExpectedFailure => s.expected_failures += 1,
                Status::Fail => s.failed += 1,
                Status::UnexpectedPass => s.unexpected_passes += 1,
                Status::Stale => s.stale += 1,
                Status::Error => s.errors += 1,
            }
        }
        s
    }

    /// The verdict of the run.
    ///
    /// # Errors
    /// [`Error::NoCaseRan`] when no case ran; [`Error::Failed`] on an
    /// unexpected failure, a case error, a listed failure that now passes or a
    /// stale list entry.
    pub fn verdict(&self) -> Result<Summary, Error> {
        let s = self.summary();
        if s.cases == 0 {
            return Err(Error::NoCaseRan);
        }
        if s.failed + s.errors + s.unexpected_passes + s.stale > 0 {
            return Err(Error::Failed {
                unexpected: s.failed,
                errors: s.errors,
                fixed: s.unexpected_passes,
                stale: s.stale,
            });
        }
        Ok(s)
    }

    /// Renders the table as GitHub markdown, with a summary line.
    #[must_use]
    pub fn to_markdown(&self) -> String {
        let mut out = String::new();
        out.push_str("| case | metric | reference | ours | tolerance | status | note |\n");
        out.push_str("|---|---|---:|---:|---|---|---|\n");
        for r in &self.rows {
            let _ = writeln!(
                out,
                "| {} | {} | {} | {} | {} | {} | {} |",
                r.case,
                r.metric,
                fmt_num(r.reference),
                fmt_num(r.ours),
                r.tolerance,
                r.status.label(),
                r.note.replace('|', "\\|")
            );
        }
        let s = self.summary();
        let _ = writeln!(
            out,
            "\n{} cases, {} checks: {} passed, {} expected failures, {} failed, {} unexpectedly passing, {} stale, {} errors",
            s.cases,
            self.rows.len(),
            s.passed,
            s.expected_failures,
            s.failed,
            s.unexpected_passes,
            s.stale,
            s.errors
        );
        out
    }

    /// Writes the table as CSV (RFC 4180 quoting) with a header row.
    ///
    /// # Errors
    /// Any error of the writer.
    pub fn write_csv(&self, mut w: impl io::Write) -> io::Result<()> {
        writeln!(w, "case,metric,reference,ours,tolerance,status,note")?;
        for r in &self.rows {
            writeln!(
                w,
                "{},{},{},{},{},{},{}",
                csv_field(&r.case),
                csv_field(&r.metric),
                csv_num(r.reference),
                csv_num(r.ours),
                csv_field(&r.tolerance),
                r.status.label(),
                csv_field(&r.note)
            )?;
        }
        Ok(())
    }
}

fn fmt_num(x: f64) -> String {
    if x.is_nan() {
        "-".to_owned()
    } else if x != 0.0 && (x.abs() < 1e-3 || x.abs() >= 1e7) {
        format!("{x:.4e}")
    } else {
        let s = format!("{x:.6}");
        let s = s.trim_end_matches('0').trim_end_matches('.');
        s.to_owned()
    }
}

fn csv_num(x: f64) -> String {
    if x.is_nan() {
        String::new()
    } else {
        format!("{x}")
    }
}

fn csv_field(s: &str) -> String {
    if s.contains([',', '"', '\n', '\r']) {
        format!("\"{}\"", s.replace('"', "\"\""))
    } else {
        s.to_owned()
    }
}

#[cfg(test)]
mod tests;
