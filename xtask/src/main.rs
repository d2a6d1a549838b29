//! grainforge's task runner: the project's only binary.
//!
//! `cargo xtask validate [--filter PATTERN] [--report DIR] [--fast]` runs the
//! reference cases of the `validate` crate, prints the result table and exits
//! non-zero on failure. `cargo xtask calibrate` (the cloner sweep) lands with
//! the `cloner` crate. The tidy checks of the workspace are `#[test]`s in
//! `tidy.rs`, run by `cargo test`.
//!
//! Heavy science stays in the libraries and is called in-process; this crate
//! only knows paths, parses flags and prints.

// The task runner is the one place that prints (see docs/architecture.md).
#![allow(clippy::print_stdout, clippy::print_stderr)]

use clap::{Parser, Subcommand};

mod validate_cmd;

#[cfg(test)]
mod tidy;

/// grainforge tasks.
#[derive(Debug, Parser)]
#[command(name = "cargo xtask", version, about)]
struct Cli {
    #[command(subcommand)]
    command: Command,
}

#[derive(Debug, Subcommand)]
enum Command {
    /// Run the reference validation cases and print the result table.
    Validate(validate_cmd::Validate),
}

fn main() -> anyhow::Result<()> {
    let cli = Cli::parse();
    match cli.command {
        Command::Validate(cmd) => cmd.run(),
    }
}
