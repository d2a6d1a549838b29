//! Reference validation runner (work in progress).
