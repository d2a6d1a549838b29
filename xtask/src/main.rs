//! grainforge's task runner: the project's only binary.
//!
//! `cargo xtask calibrate` (the main job) sweeps the cloner over the seed's
//! trial grid and writes the calibration report and fixture; `cargo xtask
//! clone` writes clones with the calibrated configuration; `cargo xtask
//! validate [--filter PATTERN] [--report DIR] [--fast]` runs the reference
//! cases of the `validate` crate, prints the result table and exits non-zero
//! on failure; `cargo xtask pack` packs a 2D domain with disks and writes it
//! for DEM tools; `cargo xtask specimen SCENE.ron` builds a DEM specimen of
//! cloned grains from a scene file; `cargo xtask dna` and `convergence`
//! write generated tables.
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
mod pack3d_cmd;
mod pack_cmd;
mod parents;
mod progress;
mod specimen;
mod svg;
mod synth_scan;
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
    /// Pack a 2D domain with disks (Pinto 2009's advancing front) or a 3D
    /// container with spheres (`--dim 3 --container …`) and write CSV, VTU
    /// (ParaView), LIGGGHTS/LAMMPS data, Yade text (and SVG in 2D).
    Pack(pack_cmd::Pack),
    /// Build a DEM specimen of cloned grains from a scene file (RON):
    /// parents, calibrated configuration, clones, container, packing preset
    /// and outputs (LS-DEM, LAMMPS/LIGGGHTS/Yade clumps, VTU, DNA and
    /// grading report); only the stages the scene needs run.
    Specimen(specimen::Specimen),
    /// Check a settled DEM deck of a specimen (lammps/, yade/ or liggghts/): no atom lost,
    /// overlaps at most 1 % of d50, solid fraction within 0.01 of the packed one.
    SpecimenCheck(specimen::check::SpecimenCheck),
    /// Write a synthetic labelled CT image of cloned grains (scale tests of
    /// `--parents`).
    SynthScan(synth_scan::SynthScan),
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
    if std::env::var_os("GRAINFORGE_NO_MALLOC_WARMUP").is_none() {
        raise_malloc_trim_threshold();
    }
    match cli.command {
        Command::Calibrate(cmd) => cmd.run(&workspace_root()),
        Command::Clone(cmd) => cmd.run(&workspace_root()),
        Command::Validate(cmd) => cmd.run(),
        Command::Dna(cmd) => cmd.run(&workspace_root()),
        Command::Convergence(cmd) => cmd.run(&workspace_root()),
        Command::Pack(cmd) => cmd.run(&workspace_root()),
        Command::SynthScan(cmd) => cmd.run(&workspace_root()),
        Command::Specimen(cmd) => cmd.run(&workspace_root()),
        Command::SpecimenCheck(cmd) => cmd.run(&workspace_root()),
    }
}

/// Allocates and frees one 16 MiB block, so that glibc's malloc keeps the
/// memory the workers free instead of handing it back to the kernel.
///
/// Why: glibc returns the free memory at the top of a thread's heap to the
/// kernel (`madvise(MADV_DONTNEED)`) once it exceeds a trim threshold of
/// twice the largest block that was ever served by `mmap` and freed (128 KiB
/// → 256 KiB at start). A cloned grain allocates and frees ≈ 4 MiB of grids,
/// meshes and scratch per level set, so without this every clone faulted its
/// memory back in: ≈ 0.8 s of kernel time in the 9 s of CPU of `calibrate
/// --check` (384,000 minor page faults). Freeing one 16 MiB block (served by
/// `mmap`: above the initial threshold) raises the threshold to 16 MiB and
/// the trim threshold to 32 MiB, as the glibc manual describes for
/// `M_MMAP_THRESHOLD`'s dynamic adjustment; kernel time falls to ≈ 0.05 s
/// and the calibrated clones/s rise by ≈ 15 % on the 2-vCPU machine. It
/// changes no result (an allocation pattern only), costs no time, and does
/// nothing on other allocators. `GRAINFORGE_NO_MALLOC_WARMUP=1` turns it off
/// (for comparison). Programs that embed the cloner can do the same.
fn raise_malloc_trim_threshold() {
    let block: Vec<u8> = Vec::with_capacity(16 << 20);
    // keep the allocation (and its free) from being optimised away
    drop(std::hint::black_box(block));
}
