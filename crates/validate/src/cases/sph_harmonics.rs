//! sph-harmonics reproductions (issue 4): Radvilaitė 2016 Tables 3.1–3.4, 3.6, 3.7 at the
//! thesis' degree and sampling; NIST/VCCTL Ottawa grains against NIST's geom table at `Nnn`;
//! Gauss–Bonnet on a real grain; our own convergence table (error vs degree).
//!
//! One submodule per group of cases, each exposing `cases()` and (where it has
//! any) `EXPECTED_FAILURES`; this module registers them in a fixed order.

use crate::{Case, Error, ExpectedFailure};

mod contact;
mod convergence;
mod elongation;
mod octant_tables;
mod vcctl;

/// Every sph-harmonics case, in registration order.
pub(crate) fn cases() -> Vec<Case> {
    let mut cases = Vec::new();
    cases.extend(octant_tables::cases());
    cases.extend(contact::cases());
    cases.extend(elongation::cases());
    cases.extend(vcctl::cases());
    cases.extend(convergence::cases());
    cases
}

/// The groups' expected failures, in the order of their cases.
const GROUP_FAILURES: [&[ExpectedFailure]; 4] = [
    octant_tables::EXPECTED_FAILURES,
    elongation::EXPECTED_FAILURES,
    vcctl::EXPECTED_FAILURES,
    convergence::EXPECTED_FAILURES,
];

/// Number of expected failures over every group.
const N_EXPECTED_FAILURES: usize = total_len(&GROUP_FAILURES);

/// Every group's expected failures, concatenated at compile time.
const ALL_EXPECTED_FAILURES: [ExpectedFailure; N_EXPECTED_FAILURES] = concat(&GROUP_FAILURES);

/// Every sph-harmonics expected failure with its reason.
pub(crate) const EXPECTED_FAILURES: &[ExpectedFailure] = &ALL_EXPECTED_FAILURES;

/// Total length of `groups`.
const fn total_len(groups: &[&[ExpectedFailure]]) -> usize {
    let mut n = 0;
    let mut g = 0;
    while g < groups.len() {
        n += groups[g].len();
        g += 1;
    }
    n
}

/// `groups` one after the other; `N` must be their total length (checked at
/// compile time).
const fn concat<const N: usize>(groups: &[&[ExpectedFailure]]) -> [ExpectedFailure; N] {
    let blank = ExpectedFailure {
        case: "",
        metric: "",
        reason: "",
    };
    let mut out = [blank; N];
    let mut n = 0;
    let mut g = 0;
    while g < groups.len() {
        let mut i = 0;
        while i < groups[g].len() {
            out[n] = groups[g][i];
            n += 1;
            i += 1;
        }
        g += 1;
    }
    assert!(n == N, "expected-failure groups do not fill the table");
    out
}

/// A `sph-harmonics` error as a case error.
fn err(e: sph_harmonics::Error) -> Error {
    Error::computation(e)
}
