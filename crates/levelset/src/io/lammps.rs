//! LAMMPS LSDEM grid files: a comment line; `nx ny nz`; the spacing; the grid minimum
//! (position of node (0,0,0)) relative to the centre of mass; then one value per line,
//! x fastest.

use std::io::{BufRead, Write};

use nalgebra::Point3;

use super::{Tokens, fmt_f64, read_dims, read_values};
use crate::error::Result;
use crate::grid::{Grid, GridSpec};

/// Writes `grid` (whose origin must already be relative to the centre of mass) with a
/// comment line (line breaks in `comment` are replaced by spaces; `# ` is prefixed).
///
/// # Errors
/// [`crate::Error::Io`] on write failure.
pub fn write_lammps(mut w: impl Write, comment: &str, grid: &Grid) -> Result<()> {
    let mut s = String::with_capacity(24 * grid.values().len() + 128);
    s.push_str("# ");
    s.push_str(&comment.replace(['\n', '\r'], " "));
    s.push('\n');
    let d = grid.dims();
    s.push_str(&format!("{} {} {}\n", d[0], d[1], d[2]));
    fmt_f64(&mut s, grid.spacing());
    s.push('\n');
    let o = grid.origin();
    for a in 0..3 {
        if a > 0 {
            s.push(' ');
        }
        fmt_f64(&mut s, o[a]);
    }
    s.push('\n');
    for &v in grid.values() {
        fmt_f64(&mut s, v);
        s.push('\n');
    }
    w.write_all(s.as_bytes())?;
    Ok(())
}

/// Reads a LAMMPS LSDEM grid file; returns the comment (without a leading `#`) and the grid
/// (origin = grid minimum relative to the centre of mass).
///
/// # Errors
/// [`crate::Error::Parse`] with the line number for malformed, truncated or non-finite
/// data, a non-positive spacing, too few nodes or trailing data.
pub fn read_lammps(r: impl BufRead) -> Result<(String, Grid)> {
    let mut t = Tokens::new(r, "lammps");
    let comment = match t.next_line()? {
        Some(l) => l.trim_start_matches('#').trim().to_string(),
        None => return Err(t.err("empty input, expected a comment line")),
    };
    let dims = read_dims(&mut t)?;
    let spacing = t.f64("spacing")?;
    if spacing <= 0.0 {
        return Err(t.err(format!("spacing must be positive, found {spacing}")));
    }
    let origin = Point3::new(
        t.f64("x minimum")?,
        t.f64("y minimum")?,
        t.f64("z minimum")?,
    );
    let values = read_values(&mut t, dims[0] * dims[1] * dims[2])?;
    t.finish()?;
    Ok((
        comment,
        Grid::new(
            GridSpec {
                dims,
                origin,
                spacing,
            },
            values,
        )?,
    ))
}
