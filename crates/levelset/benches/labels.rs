//! Label bench (placeholder).
fn main() {}
