//! Test-only studies of the cases (slow, ignored by default).

mod roundness_ambiguity;
