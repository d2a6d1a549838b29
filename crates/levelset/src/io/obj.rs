//! Wavefront OBJ polygon meshes (the geometry subset: `v` and `f`).
//!
//! Design choices:
//! * **Only what makes a surface is read.** `v x y z [w]` (up to four further numbers, such
//!   as the vertex colours some exporters append, are parsed and ignored) and `f` with the
//!   `v`, `v/vt`, `v//vn` and `v/vt/vn` forms; texture and normal indices are checked for
//!   syntax only. Grouping, material and display statements (`o g s usemtl mtllib vt vn vp
//!   l p lod bevel c_interp d_interp shadow_obj trace_obj maplib usemap`) are ignored.
//!   Free-form geometry (`cstype`, `curv`, `surf`, …) and unknown statements are errors:
//!   silently skipping them could lose part of the grain.
//! * **Indices** are 1-based; negative indices count back from the last vertex defined so
//!   far (`-1` is the latest). Positive indices may refer to vertices defined later in the
//!   file (some exporters write faces first); they are checked once the file is read, and
//!   the error still names the face's line.
//! * **Polygons are fan-triangulated** from their first corner: `(p0, p1, p2), (p0, p2,
//!   p3), …`, which keeps the polygon's orientation and is exact for convex (or
//!   star-shaped from `p0`) planar polygons. Non-convex polygons can yield overlapping
//!   triangles; grain meshes (scans, marching cubes) are triangles or convex quads.
//! * **No welding in the reader**: OBJ shares vertices by index already, and keeping the
//!   file's numbering means vertex `i` of the mesh is the `(i+1)`-th `v` line, so the
//!   vertex indices in the errors of [`TriMesh::prepare_closed`] point into the file. That
//!   function welds duplicated positions (UV seams) itself and reports how many.
//!   Degenerate faces are kept for it to count and drop, too.
//! * Comments run from `#` to the end of the line; a line ending in `\` continues on the
//!   next one. Every error names the 1-based line ([`Error::Parse`]).

use std::io::{BufRead, Write};

use nalgebra::Point3;

use super::{MAX_PREALLOC, fmt_f64};
use crate::error::{Error, Result};
use crate::mesh::TriMesh;

/// Statements that carry no geometry of a polygonal surface.
const IGNORED: &[&str] = &[
    "vt",
    "vn",
    "vp",
    "o",
    "g",
    "s",
    "usemtl",
    "mtllib",
    "l",
    "p",
    "lod",
    "bevel",
    "c_interp",
    "d_interp",
    "shadow_obj",
    "trace_obj",
    "maplib",
    "usemap",
];

/// Free-form geometry statements.
const FREE_FORM: &[&str] = &[
    "cstype", "deg", "bmat", "step", "curv", "curv2", "surf", "parm", "trim", "hole", "scrv", "sp",
    "end", "con",
];

fn err(line: usize, reason: impl Into<String>) -> Error {
    Error::Parse {
        format: "obj",
        line: line.max(1),
        reason: reason.into(),
    }
}

/// A corner's vertex index as written: 1-based, or negative (relative).
fn parse_corner(tok: &str, line: usize) -> Result<i64> {
    let mut parts = tok.split('/');
    let v = parts.next().unwrap_or_default();
    let index: i64 = v.parse().map_err(|_| {
        err(
            line,
            format!("expected a vertex index in face corner {tok:?}, found {v:?}"),
        )
    })?;
    if index == 0 {
        return Err(err(
            line,
            format!("vertex index 0 in face corner {tok:?} (OBJ indices start at 1)"),
        ));
    }
    let mut extra = 0;
    for p in parts {
        extra += 1;
        if extra > 2 {
            return Err(err(
                line,
                format!("face corner {tok:?} has more than three fields (v/vt/vn)"),
            ));
        }
        if !p.is_empty() && p.parse::<i64>().is_err() {
            return Err(err(
                line,
                format!("expected a texture or normal index in face corner {tok:?}, found {p:?}"),
            ));
        }
    }
    Ok(index)
}

/// Reads the polygonal surface of an OBJ file into a [`TriMesh`] (file vertex numbering,
/// polygons fan-triangulated, degenerate triangles kept: see the module docs, and
/// [`TriMesh::prepare_closed`] for turning it into a closed grain).
///
/// # Errors
/// [`Error::Parse`] with the line for: a malformed number or index, a non-finite
/// coordinate, a face with fewer than 3 corners, an index 0 or out of range (positive or
/// relative), free-form geometry or an unknown statement, or no faces at all;
/// [`Error::Io`] if reading fails.
pub fn read_obj(mut r: impl BufRead) -> Result<TriMesh> {
    let mut vertices: Vec<Point3<f64>> = Vec::new();
    // Triangles with the line of their face; positive indices are checked at the end.
    let mut triangles: Vec<[usize; 3]> = Vec::new();
    let mut face_lines: Vec<usize> = Vec::new();
    let mut line = 0usize;
    let mut buf = Vec::new();
    let mut statement = String::new();
    let mut corners: Vec<usize> = Vec::new();
    loop {
        // One statement: a line plus its `\` continuations.
        statement.clear();
        let mut start = 0;
        let mut eof = true;
        loop {
            buf.clear();
            if r.read_until(b'\n', &mut buf)? == 0 {
                break;
            }
            eof = false;
            line += 1;
            if start == 0 {
                start = line;
            }
            // Comments first, then text: names in other encodings must not fail a file
            // (bytes that are not UTF-8 become U+FFFD and fail only where a number is due).
            let code = buf.split(|&b| b == b'#').next().unwrap_or_default();
            let text = String::from_utf8_lossy(code);
            let text = text.trim_end();
            match text.strip_suffix('\\') {
                Some(head) => {
                    statement.push_str(head);
                    statement.push(' ');
                }
                None => {
                    statement.push_str(text);
                    break;
                }
            }
        }
        if eof {
            break;
        }
        let mut tokens = statement.split_ascii_whitespace();
        let Some(keyword) = tokens.next() else {
            continue;
        };
        match keyword {
            "v" => {
                let mut xyz = [0.0; 3];
                let mut n = 0;
                for tok in tokens {
                    let x: f64 = tok
                        .parse()
                        .map_err(|_| err(start, format!("expected a number, found {tok:?}")))?;
                    if n < 3 {
                        if !x.is_finite() {
                            return Err(err(
                                start,
                                format!("vertex coordinate {tok:?} is not finite"),
                            ));
                        }
                        xyz[n] = x;
                    }
                    n += 1;
                }
                if !(3..=7).contains(&n) {
                    return Err(err(
                        start,
                        format!(
                            "a vertex needs 3 coordinates (and at most 4 more values), found {n} values"
                        ),
                    ));
                }
                vertices.push(Point3::from(xyz));
            }
            "f" => {
                corners.clear();
                for tok in tokens {
                    let index = parse_corner(tok, start)?;
                    let resolved = if index > 0 {
                        usize::try_from(index - 1).ok()
                    } else {
                        usize::try_from(index.unsigned_abs())
                            .ok()
                            .and_then(|back| vertices.len().checked_sub(back))
                    };
                    let Some(resolved) = resolved else {
                        return Err(err(
                            start,
                            format!(
                                "relative vertex index {index} but only {} vertices are defined so far",
                                vertices.len()
                            ),
                        ));
                    };
                    corners.push(resolved);
                }
                if corners.len() < 3 {
                    return Err(err(
                        start,
                        format!("a face needs at least 3 vertices, found {}", corners.len()),
                    ));
                }
                for k in 1..corners.len() - 1 {
                    triangles.push([corners[0], corners[k], corners[k + 1]]);
                    face_lines.push(start);
                }
            }
            k if IGNORED.contains(&k) => {}
            k if FREE_FORM.contains(&k) => {
                return Err(err(
                    start,
                    format!("free-form geometry ('{k}') is not supported; export polygons"),
                ));
            }
            k => return Err(err(start, format!("unknown statement {k:?}"))),
        }
    }
    if triangles.is_empty() {
        return Err(err(line, "no faces"));
    }
    let n = vertices.len();
    if let Some((t, &i)) = triangles
        .iter()
        .enumerate()
        .find_map(|(t, tri)| tri.iter().find(|&&i| i >= n).map(|i| (t, i)))
    {
        return Err(err(
            face_lines[t],
            format!(
                "vertex index {} but the file defines {n} vertices",
                i.saturating_add(1)
            ),
        ));
    }
    TriMesh::new_allowing_degenerate(vertices, triangles)
        .map_err(|e| err(line, format!("invalid mesh: {e}")))
}

/// Writes a mesh as OBJ: a comment, `v x y z` lines (shortest round-trip floats, so
/// [`read_obj`] gives back the identical mesh) and 1-based `f a b c` lines.
///
/// # Errors
/// [`Error::Io`] on write failure.
pub fn write_obj(mut w: impl Write, mesh: &TriMesh) -> Result<()> {
    let (nv, nt) = (mesh.vertices().len(), mesh.triangles().len());
    let mut s = String::with_capacity((60 * nv + 30 * nt + 80).min(64 * MAX_PREALLOC));
    s.push_str(&format!(
        "# OBJ written by grainforge levelset: {nv} vertices, {nt} triangles\n"
    ));
    for p in mesh.vertices() {
        s.push('v');
        for &x in p.coords.iter() {
            s.push(' ');
            fmt_f64(&mut s, x);
        }
        s.push('\n');
    }
    for [a, b, c] in mesh.triangles() {
        s.push_str(&format!("f {} {} {}\n", a + 1, b + 1, c + 1));
    }
    w.write_all(s.as_bytes())?;
    Ok(())
}
