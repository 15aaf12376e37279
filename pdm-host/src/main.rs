//! The `pdm` command line.
fn main() {}
