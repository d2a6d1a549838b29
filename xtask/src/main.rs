//! grainforge task runner.
fn main() {}
