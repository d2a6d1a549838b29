//! STL meshes, binary and ASCII. The reader welds bit-identical vertex positions into an
//! indexed [`TriMesh`] (STL stores every facet's corners separately) and keeps degenerate
//! facets, which real files contain: [`TriMesh::prepare_closed`] counts and drops them and
//! checks that the result is one closed, oriented grain.
//!
//! Binary or ASCII is decided by size, not by the header: a binary file is exactly
//! 84 + 50·count bytes, and exporters (SolidWorks among them) often begin the 80-byte
//! binary header with `solid`, so the header's first word proves nothing.

use std::io::{BufRead, Write};

use nalgebra::{Point3, Vector3};

use super::{MAX_PREALLOC, Tokens, fmt_f64};
use crate::error::{Error, Result};
use crate::mesh::TriMesh;

fn facet_normal(mesh: &TriMesh, t: &[usize; 3]) -> Vector3<f64> {
    let v = mesh.vertices();
    let n = (v[t[1]] - v[t[0]]).cross(&(v[t[2]] - v[t[0]]));
    n.try_normalize(0.0).unwrap_or_else(Vector3::zeros)
}

/// Writes ASCII STL (`solid name … endsolid name`).
///
/// # Errors
/// [`Error::Io`] on write failure.
pub fn write_stl_ascii(mut w: impl Write, name: &str, mesh: &TriMesh) -> Result<()> {
    let name: String = name.chars().filter(|c| !c.is_whitespace()).collect();
    let mut s = String::with_capacity(256 * mesh.triangles().len() + 64);
    s.push_str(&format!("solid {name}\n"));
    let v3 = |s: &mut String, p: &[f64]| {
        for &x in p {
            s.push(' ');
            fmt_f64(s, x);
        }
        s.push('\n');
    };
    for t in mesh.triangles() {
        s.push_str("  facet normal");
        v3(&mut s, facet_normal(mesh, t).as_slice());
        s.push_str("    outer loop\n");
        for &i in t {
            s.push_str("      vertex");
            v3(&mut s, mesh.vertices()[i].coords.as_slice());
        }
        s.push_str("    endloop\n  endfacet\n");
    }
    s.push_str(&format!("endsolid {name}\n"));
    w.write_all(s.as_bytes())?;
    Ok(())
}

/// Writes binary STL (80-byte header, little-endian f32 coordinates).
///
/// # Errors
/// [`Error::Io`] on write failure; [`Error::InvalidParameter`] for more than 2³² − 1
/// triangles.
pub fn write_stl_binary(mut w: impl Write, mesh: &TriMesh) -> Result<()> {
    let count = u32::try_from(mesh.triangles().len()).map_err(|_| Error::InvalidParameter {
        name: "triangle count",
        value: mesh.triangles().len() as f64,
        requirement: "below 2^32 for binary STL",
    })?;
    let mut buf = Vec::with_capacity(84 + 50 * mesh.triangles().len());
    let mut header = [b' '; 80];
    let tag = b"binary STL written by grainforge levelset";
    header[..tag.len()].copy_from_slice(tag);
    buf.extend_from_slice(&header);
    buf.extend_from_slice(&count.to_le_bytes());
    for t in mesh.triangles() {
        let n = facet_normal(mesh, t);
        for x in n.iter() {
            buf.extend_from_slice(&(*x as f32).to_le_bytes());
        }
        for &i in t {
            for x in mesh.vertices()[i].coords.iter() {
                buf.extend_from_slice(&(*x as f32).to_le_bytes());
            }
        }
        buf.extend_from_slice(&0u16.to_le_bytes());
    }
    w.write_all(&buf)?;
    Ok(())
}

/// Welds bit-identical positions (`-0.0` and `0.0` are one position) into an indexed mesh;
/// degenerate triangles are kept for [`TriMesh::prepare_closed`] to count and drop.
pub(crate) fn weld(corners: Vec<Point3<f64>>, format: &'static str) -> Result<TriMesh> {
    let mut order: Vec<usize> = (0..corners.len()).collect();
    let key = |p: &Point3<f64>| {
        [
            (p.x + 0.0).to_bits(),
            (p.y + 0.0).to_bits(),
            (p.z + 0.0).to_bits(),
        ]
    };
    order.sort_by_key(|&i| key(&corners[i]));
    let mut index = vec![0usize; corners.len()];
    let mut vertices: Vec<Point3<f64>> = Vec::new();
    for (n, &i) in order.iter().enumerate() {
        if n == 0 || key(&corners[i]) != key(&corners[order[n - 1]]) {
            vertices.push(corners[i]);
        }
        index[i] = vertices.len() - 1;
    }
    let triangles = index.chunks_exact(3).map(|c| [c[0], c[1], c[2]]).collect();
    TriMesh::new_allowing_degenerate(vertices, triangles).map_err(|e| Error::Parse {
        format,
        line: 0,
        reason: format!("invalid mesh: {e}"),
    })
}

/// Reads binary or ASCII STL into a welded [`TriMesh`] (degenerate facets kept; see
/// [`TriMesh::prepare_closed`]).
///
/// The data are binary if their size is exactly 84 + 50·count bytes (count = the
/// little-endian `u32` at byte 80), whatever the header says — many binary files start
/// with `solid` — and otherwise ASCII if they start with `solid`. ASCII: keywords are
/// whitespace-separated (any line breaks, CRLF included), the name after `solid` is the
/// words on its line before the first `facet`/`endsolid`, the name after `endsolid` the
/// rest of its line, numbers in any Rust float syntax (scientific
/// notation included), facet normals are read but ignored (they may even be `nan`),
/// names may be in any encoding, and several `solid … endsolid` blocks are concatenated.
///
/// # Errors
/// [`Error::Parse`] for malformed or truncated data (line number for ASCII, byte offset
/// in the reason for binary), non-finite vertex coordinates, or no facets.
pub fn read_stl(mut r: impl BufRead) -> Result<TriMesh> {
    let mut data = Vec::new();
    r.read_to_end(&mut data)?;
    let declared = data
        .get(80..84)
        .and_then(|b| <[u8; 4]>::try_from(b).ok())
        .map(|b| u32::from_le_bytes(b) as u64);
    if let Some(count) = declared
        && 84 + 50 * count == data.len() as u64
    {
        return read_binary(&data);
    }
    let size_note = match declared {
        Some(count) => format!("size {} ≠ 84 + 50·{count}", data.len()),
        None => format!("size {} < 84", data.len()),
    };
    let head = data
        .iter()
        .skip_while(|b| b.is_ascii_whitespace())
        .take(5)
        .copied();
    if !head.eq(b"solid".iter().copied()) {
        return Err(Error::Parse {
            format: "stl",
            line: 0,
            reason: format!("neither binary STL ({size_note}) nor ASCII STL (no 'solid')"),
        });
    }
    read_ascii(&data).map_err(|e| {
        // A binary file with a `solid` header and a wrong size: say so rather than
        // reporting a confusing token error.
        let binary = data
            .iter()
            .position(|&b| !(b.is_ascii_graphic() || b.is_ascii_whitespace()));
        match (e, binary) {
            (Error::Parse { line, reason, .. }, Some(offset)) => Error::Parse {
                format: "stl",
                line,
                reason: format!(
                    "{reason}; the data are not ASCII (byte offset {offset}) and not binary \
                     STL ({size_note})"
                ),
            },
            (e, _) => e,
        }
    })
}

/// Binary STL whose size has been checked: 84 bytes of header and count, then 50 bytes per
/// facet (normal, three corners, attribute).
fn read_binary(data: &[u8]) -> Result<TriMesh> {
    let body = data.get(84..).unwrap_or_default();
    let mut corners = Vec::with_capacity((3 * (body.len() / 50)).min(MAX_PREALLOC));
    for (t, facet) in body.chunks_exact(50).enumerate() {
        for (k, x) in facet[12..48].chunks_exact(4).enumerate() {
            let v = f32::from_le_bytes([x[0], x[1], x[2], x[3]]);
            if !v.is_finite() {
                let o = 84 + 50 * t + 12 + 4 * k;
                return Err(Error::Parse {
                    format: "stl",
                    line: 0,
                    reason: format!("non-finite coordinate {v} at byte offset {o} (facet {t})"),
                });
            }
        }
        let f = |k: usize| {
            let o = 12 + 4 * k;
            f64::from(f32::from_le_bytes([
                facet[o],
                facet[o + 1],
                facet[o + 2],
                facet[o + 3],
            ]))
        };
        for c in 0..3 {
            corners.push(Point3::new(f(3 * c), f(3 * c + 1), f(3 * c + 2)));
        }
    }
    weld(corners, "stl")
}

fn read_ascii(data: &[u8]) -> Result<TriMesh> {
    let mut t = Tokens::new(data, "stl").lossy();
    let mut corners = Vec::new();
    let mut tok = t.expect("solid")?;
    while tok == "solid" {
        // The name: any words on the line of `solid` before the first `facet`/`endsolid`.
        let line = t.line();
        tok = t.expect("facet or endsolid")?;
        while tok != "facet" && tok != "endsolid" {
            if t.line() != line {
                return Err(t.err(format!("expected 'facet' or 'endsolid', found {tok:?}")));
            }
            tok = t.expect("facet or endsolid")?;
        }
        while tok == "facet" {
            let kw = t.expect("normal")?;
            if kw != "normal" {
                return Err(t.err(format!("expected 'normal', found {kw:?}")));
            }
            for _ in 0..3 {
                // Ignored; exporters write `nan` for degenerate facets.
                let n = t.expect("normal component")?;
                if n.parse::<f64>().is_err() {
                    return Err(t.err(format!("expected a normal component, found {n:?}")));
                }
            }
            for word in ["outer", "loop"] {
                let kw = t.expect(word)?;
                if kw != word {
                    return Err(t.err(format!("expected {word:?}, found {kw:?}")));
                }
            }
            for _ in 0..3 {
                let kw = t.expect("vertex")?;
                if kw != "vertex" {
                    return Err(t.err(format!("expected 'vertex', found {kw:?}")));
                }
                corners.push(Point3::new(t.f64("x")?, t.f64("y")?, t.f64("z")?));
            }
            for word in ["endloop", "endfacet"] {
                let kw = t.expect(word)?;
                if kw != word {
                    return Err(t.err(format!("expected {word:?}, found {kw:?}")));
                }
            }
            tok = t.expect("facet or endsolid")?;
        }
        if tok != "endsolid" {
            return Err(t.err(format!("expected 'facet' or 'endsolid', found {tok:?}")));
        }
        // The name after `endsolid` is the rest of its line; then the end or another solid.
        t.skip_rest_of_line();
        match t.next_token()? {
            None => break,
            Some(next) if next == "solid" => tok = next,
            Some(next) => {
                return Err(t.err(format!(
                    "unexpected {next:?} after 'endsolid' (expected 'solid' or the end)"
                )));
            }
        }
    }
    if corners.is_empty() {
        return Err(t.err("no facets"));
    }
    let line = t.line();
    weld(corners, "stl").map_err(|e| match e {
        Error::Parse { format, reason, .. } => Error::Parse {
            format,
            line,
            reason,
        },
        other => other,
    })
}
