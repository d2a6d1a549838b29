//! VTK legacy files, `DATASET STRUCTURED_POINTS`, ASCII (opens in ParaView).

use std::io::{BufRead, Write};

use nalgebra::Point3;

use super::{Tokens, fmt_f64, read_dims, read_values};
use crate::error::Result;
use crate::grid::{Grid, GridSpec};

/// Writes the grid as point data `phi` (double) with the given title line.
///
/// # Errors
/// [`crate::Error::Io`] on write failure.
pub fn write_vtk(mut w: impl Write, title: &str, grid: &Grid) -> Result<()> {
    let mut s = String::with_capacity(24 * grid.values().len() + 256);
    s.push_str("# vtk DataFile Version 3.0\n");
    let title: String = title.replace(['\n', '\r'], " ").chars().take(255).collect();
    s.push_str(if title.is_empty() { "levelset" } else { &title });
    s.push_str("\nASCII\nDATASET STRUCTURED_POINTS\n");
    let d = grid.dims();
    s.push_str(&format!("DIMENSIONS {} {} {}\nORIGIN", d[0], d[1], d[2]));
    for a in 0..3 {
        s.push(' ');
        fmt_f64(&mut s, grid.origin()[a]);
    }
    s.push_str("\nSPACING");
    for _ in 0..3 {
        s.push(' ');
        fmt_f64(&mut s, grid.spacing());
    }
    s.push_str(&format!(
        "\nPOINT_DATA {}\nSCALARS phi double 1\nLOOKUP_TABLE default\n",
        grid.values().len()
    ));
    for &v in grid.values() {
        fmt_f64(&mut s, v);
        s.push('\n');
    }
    w.write_all(s.as_bytes())?;
    Ok(())
}

/// Reads an ASCII structured-points file with one scalar field (the first `SCALARS`);
/// returns the title and the grid.
///
/// # Errors
/// [`crate::Error::Parse`] with the line number for a wrong header, BINARY data, another
/// dataset type, unequal or non-positive spacing, a point count that does not match the
/// dimensions, more than one component, or malformed/truncated values.
pub fn read_vtk(r: impl BufRead) -> Result<(String, Grid)> {
    let mut t = Tokens::new(r, "vtk");
    match t.next_line()? {
        Some(l) if l.starts_with("# vtk DataFile Version") => {}
        _ => return Err(t.err("missing '# vtk DataFile Version' header")),
    }
    let title = t.next_line()?.ok_or_else(|| t.err("missing title line"))?;
    let fmt = t.expect("ASCII")?;
    if !fmt.eq_ignore_ascii_case("ASCII") {
        return Err(t.err(format!("only ASCII files are supported, found {fmt:?}")));
    }
    let kw = t.expect("DATASET")?;
    let ds = t.expect("dataset type")?;
    if !kw.eq_ignore_ascii_case("DATASET") || !ds.eq_ignore_ascii_case("STRUCTURED_POINTS") {
        return Err(t.err(format!(
            "expected DATASET STRUCTURED_POINTS, found {kw} {ds}"
        )));
    }
    let mut dims = None;
    let mut origin = None;
    let mut spacing = None;
    loop {
        let kw = t
            .expect("DIMENSIONS, ORIGIN, SPACING or POINT_DATA")?
            .to_ascii_uppercase();
        match kw.as_str() {
            "DIMENSIONS" => dims = Some(read_dims(&mut t)?),
            "ORIGIN" => {
                origin = Some(Point3::new(
                    t.f64("origin")?,
                    t.f64("origin")?,
                    t.f64("origin")?,
                ))
            }
            "SPACING" | "ASPECT_RATIO" => {
                let s = [t.f64("spacing")?, t.f64("spacing")?, t.f64("spacing")?];
                if s.iter().any(|&x| x <= 0.0) {
                    return Err(t.err(format!("spacing must be positive, found {s:?}")));
                }
                if (s[1] - s[0]).abs() > 1e-9 * s[0] || (s[2] - s[0]).abs() > 1e-9 * s[0] {
                    return Err(t.err(format!("spacing must be equal on all axes, found {s:?}")));
                }
                spacing = Some(s[0]);
            }
            "POINT_DATA" => break,
            _ => return Err(t.err(format!("unexpected keyword {kw:?}"))),
        }
    }
    let n = t.usize("point count")?;
    let (Some(dims), Some(origin), Some(spacing)) = (dims, origin, spacing) else {
        return Err(t.err("DIMENSIONS, ORIGIN and SPACING must precede POINT_DATA"));
    };
    if n != dims[0] * dims[1] * dims[2] {
        return Err(t.err(format!("POINT_DATA {n} does not match DIMENSIONS {dims:?}")));
    }
    let kw = t.expect("SCALARS")?;
    if !kw.eq_ignore_ascii_case("SCALARS") {
        return Err(t.err(format!("expected SCALARS, found {kw:?}")));
    }
    let _name = t.expect("scalar name")?;
    let _ty = t.expect("scalar type")?;
    // Optional component count, then optional LOOKUP_TABLE.
    let line_before = t.line();
    let mut first_value: Option<String> = None;
    let tok = t.expect("LOOKUP_TABLE or values")?;
    let tok = if t.line() == line_before && tok.parse::<usize>().is_ok() {
        if tok != "1" {
            return Err(t.err(format!("only 1 component is supported, found {tok}")));
        }
        t.expect("LOOKUP_TABLE or values")?
    } else {
        tok
    };
    if tok.eq_ignore_ascii_case("LOOKUP_TABLE") {
        let _table = t.expect("lookup table name")?;
    } else {
        first_value = Some(tok);
    }
    let mut values = Vec::new();
    if let Some(tok) = first_value {
        let v: f64 = tok
            .parse()
            .map_err(|_| t.err(format!("expected a value, found {tok:?}")))?;
        if !v.is_finite() {
            return Err(t.err(format!("value is not finite: {tok:?}")));
        }
        values.push(v);
    }
    values.extend(read_values(&mut t, n - values.len())?);
    t.finish()?;
    Ok((
        title,
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
