//! STL meshes, binary and ASCII. The reader welds bit-identical vertex positions into an
//! indexed [`TriMesh`].

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

/// Welds exactly equal positions and builds a validated mesh.
fn weld(corners: Vec<Point3<f64>>, format: &'static str) -> Result<TriMesh> {
    let mut order: Vec<usize> = (0..corners.len()).collect();
    let key = |p: &Point3<f64>| [p.x.to_bits(), p.y.to_bits(), p.z.to_bits()];
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
    TriMesh::new(vertices, triangles).map_err(|e| Error::Parse {
        format,
        line: 0,
        reason: format!("invalid mesh: {e}"),
    })
}

/// Reads binary or ASCII STL (binary if the size is exactly 84 + 50·count bytes, else ASCII
/// when the data start with `solid`).
///
/// # Errors
/// [`Error::Parse`] for malformed or truncated data (line number for ASCII, byte offset
/// in the reason for binary), non-finite coordinates, or degenerate triangles.
pub fn read_stl(mut r: impl BufRead) -> Result<TriMesh> {
    let mut data = Vec::new();
    r.read_to_end(&mut data)?;
    if data.len() >= 84 {
        let count = u32::from_le_bytes([data[80], data[81], data[82], data[83]]) as usize;
        if count.checked_mul(50).and_then(|v| v.checked_add(84)) == Some(data.len()) {
            return read_binary(&data, count);
        }
    }
    let head = data
        .iter()
        .skip_while(|b| b.is_ascii_whitespace())
        .take(5)
        .copied();
    if head.eq(b"solid".iter().copied()) {
        return read_ascii(&data);
    }
    Err(Error::Parse {
        format: "stl",
        line: 0,
        reason: format!(
            "neither binary STL (size {} ≠ 84 + 50·count) nor ASCII STL (no 'solid')",
            data.len()
        ),
    })
}

fn read_binary(data: &[u8], count: usize) -> Result<TriMesh> {
    let mut corners = Vec::with_capacity((3 * count).min(MAX_PREALLOC));
    for t in 0..count {
        let base = 84 + 50 * t + 12;
        for c in 0..3 {
            let mut p = [0.0; 3];
            for (a, x) in p.iter_mut().enumerate() {
                let o = base + 12 * c + 4 * a;
                let v = f32::from_le_bytes([data[o], data[o + 1], data[o + 2], data[o + 3]]);
                if !v.is_finite() {
                    return Err(Error::Parse {
                        format: "stl",
                        line: 0,
                        reason: format!("non-finite coordinate at byte offset {o}"),
                    });
                }
                *x = f64::from(v);
            }
            corners.push(Point3::new(p[0], p[1], p[2]));
        }
    }
    weld(corners, "stl")
}

fn read_ascii(data: &[u8]) -> Result<TriMesh> {
    let mut t = Tokens::new(data, "stl");
    let _solid = t.expect("solid")?;
    // The name is optional and may be several words: skip to the first `facet`/`endsolid`.
    let mut corners = Vec::new();
    let mut tok = t.expect("facet or endsolid")?;
    while tok != "facet" && tok != "endsolid" {
        tok = t.expect("facet or endsolid")?;
    }
    while tok == "facet" {
        let kw = t.expect("normal")?;
        if kw != "normal" {
            return Err(t.err(format!("expected 'normal', found {kw:?}")));
        }
        for _ in 0..3 {
            t.f64("normal component")?;
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
