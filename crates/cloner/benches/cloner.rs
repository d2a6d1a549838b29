//! Criterion benches of the cloner (filled in below).
fn main() {}
