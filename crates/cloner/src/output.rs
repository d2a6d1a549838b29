//! Writers of a clone's outputs, through `impl Write` (the library opens no
//! file): LS-DEM morph files, VTK structured points (ParaView) and STL
//! surfaces of its level set. DNA tables use `morph_dna::DnaTable`'s own
//! CSV/RON writers ([`crate::Run::dna_table`]).

use std::io::Write;

use levelset::Grid;
use levelset::io::{MorphFile, write_morph, write_stl_binary, write_vtk};

use crate::error::{Error, Result};

/// Output formats of one clone's level set.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Format {
    /// LS-DEM morph file (Kawamoto et al. 2016) with the given surface node
    /// count and a density of 1 in grid units.
    LsDem {
        /// Surface nodes for LS-DEM contact.
        nodes: usize,
    },
    /// VTK legacy structured points of the level set (ParaView).
    Vtk,
    /// Binary STL of the marching-cubes surface.
    Stl,
}

/// Writes `grid` in `format`.
///
/// # Errors
/// [`Error::LevelSet`] for a grid the format cannot represent, and
/// [`Error::Write`] when the writer fails.
pub fn write_grid(grid: &Grid, format: Format, title: &str, w: impl Write) -> Result<()> {
    let io = |e: levelset::Error| match e {
        levelset::Error::Io(_) => Error::Write {
            what: "clone level set",
            message: e.to_string(),
        },
        other => Error::from(other),
    };
    match format {
        Format::LsDem { nodes } => {
            let m = MorphFile::from_grid(grid, 1.0, nodes)?;
            write_morph(w, &m).map_err(io)
        }
        Format::Vtk => write_vtk(w, title, grid).map_err(io),
        Format::Stl => write_stl_binary(w, &grid.marching_cubes()).map_err(io),
    }
}
