//! grainforge's task runner: the project's only binary.
//!
//! `cargo xtask calibrate` (the main job) sweeps the cloner over the seed's
//! trial grid and writes the calibration report and fixture; `cargo xtask
//! clone` writes clones with the calibrated configuration; `cargo xtask
//! validate [--filter PATTERN] [--report DIR] [--fast]` runs the reference
//! cases of the `validate` crate, prints the result table and exits non-zero
//! on failure; `cargo xtask dna` and `convergence` write generated tables.
//! The tidy checks of the workspace are `#[test]`s in `tidy.rs`, run by
//! `cargo test`.
//!
//! Heavy science stays in the libraries and is called in-process; this crate
//! only knows paths, parses flags and prints.

// The task runner is the one place that prints (see docs/architecture.md).
#![allow(clippy::print_stdout, clippy::print_stderr)]

use clap::{Parser, Subcommand};

mod calibrate;
mod clone_cmd;
mod convergence;
mod dna;
mod svg;
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
    /// The main job: sweep the cloner over the seed's trial grid on the real
    /// Ottawa-sand parents and write the calibration report
    /// (`--check` re-scores the committed calibration).
    Calibrate(calibrate::Calibrate),
    /// Generate clones with the calibrated configuration and write them
    /// (LS-DEM morph files, optional VTK/STL, DNA tables).
    Clone(clone_cmd::Clone),
    /// Run the reference validation cases and print the result table.
    Validate(validate_cmd::Validate),
    /// Measure the morphological DNA of every shipped real grain into
    /// `fixtures/dna/` (`--check` verifies the committed table).
    Dna(dna::Dna),
    /// Write the spherical-harmonic convergence table of the reference
    /// shapes (degree 1..30).
    Convergence(convergence::Convergence),
}

/// The workspace root (xtask's parent folder).
fn workspace_root() -> std::path::PathBuf {
    std::path::Path::new(env!("CARGO_MANIFEST_DIR"))
        .parent()
        .map_or_else(
            || std::path::PathBuf::from("."),
            std::path::Path::to_path_buf,
        )
}

fn main() -> anyhow::Result<()> {
    let cli = Cli::parse();
    match cli.command {
        Command::Calibrate(cmd) => cmd.run(&workspace_root()),
        Command::Clone(cmd) => cmd.run(&workspace_root()),
        Command::Validate(cmd) => cmd.run(),
        Command::Dna(cmd) => cmd.run(&workspace_root()),
        Command::Convergence(cmd) => cmd.run(&workspace_root()),
    }
}
