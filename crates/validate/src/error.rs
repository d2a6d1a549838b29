//! The one error type of the `validate` crate.

use thiserror::Error;

/// Everything that can go wrong while loading fixtures, running a case or
/// judging a run.
#[derive(Debug, Error, Clone, PartialEq)]
#[non_exhaustive]
pub enum Error {
    /// No embedded fixture has this name.
    #[error("no fixture named {name}")]
    MissingFixture {
        /// The name that was asked for (relative to its fixture folder).
        name: String,
    },
    /// A CSV table is malformed.
    #[error("{table}:{line}: {message}")]
    Csv {
        /// Table file name.
        table: String,
        /// 1-based line number in the file.
        line: usize,
        /// What is wrong.
        message: String,
    },
    /// A table lacks a column a case needs.
    #[error("{table}: no column {column}")]
    MissingColumn {
        /// Table file name.
        table: String,
        /// The missing column.
        column: String,
    },
    /// A cell that must hold a number does not.
    #[error("{table}:{line}: column {column}: {value:?} is not a number")]
    NotANumber {
        /// Table file name.
        table: String,
        /// 1-based line number in the file.
        line: usize,
        /// Column name.
        column: String,
        /// The cell as written.
        value: String,
    },
    /// A row a case needs is absent.
    #[error("{table}: no row where {column} = {value:?}")]
    MissingRow {
        /// Table file name.
        table: String,
        /// Column that was searched.
        column: String,
        /// Value that was searched for.
        value: String,
    },
    /// A case could not compute its result (a library returned an error).
    #[error("case computation failed: {message}")]
    Computation {
        /// The library's error, rendered.
        message: String,
    },
    /// The run selected no case at all (a filter that matches nothing, or an
    /// empty registry): a validation that checks nothing must not pass.
    #[error("no case ran")]
    NoCaseRan,
    /// The run had failures that are not on the expected-failure list, case
    /// errors, listed failures that now pass, or stale list entries.
    #[error(
        "validation failed: {unexpected} unexpected failure(s), {errors} case error(s), \
         {fixed} expected failure(s) now passing (remove them from the list), \
         {stale} stale expected-failure entr(y/ies)"
    )]
    Failed {
        /// Checks that failed and are not listed.
        unexpected: usize,
        /// Cases that returned an error.
        errors: usize,
        /// Listed expected failures that passed.
        fixed: usize,
        /// Listed expected failures whose case ran but produced no such metric.
        stale: usize,
    },
}

impl Error {
    /// Wraps any library error as a [`Error::Computation`].
    pub fn computation(err: impl std::fmt::Display) -> Self {
        Self::Computation {
            message: err.to_string(),
        }
    }
}
