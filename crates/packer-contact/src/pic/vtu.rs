//! [`write_pic_vtu`]: a packing of any shape as a VTK unstructured grid.

use nalgebra::SVector;

use super::front::PicPacking;
use crate::error::{Error, Result};
use crate::shapes::{Geometry, ParryConvex};

/// Writes a packing of any shape as a VTK unstructured grid (ParaView):
/// one cell per element, with cell arrays `grain` (index) and `radius`.
/// Disks/spheres are vertex cells, capsule cores line cells (use a Tube
/// filter with `radius`), convex polygons polygon cells and convex
/// polyhedra their hull triangles (radius 0). 2D grains are written at
/// `z = 0`.
///
/// # Errors
/// [`Error::Empty`] for an empty packing, [`Error::Io`].
pub fn write_pic_vtu<const D: usize>(p: &PicPacking<D>, mut w: impl std::io::Write) -> Result<()> {
    if p.grains.is_empty() {
        return Err(Error::Empty { what: "packing" });
    }
    let mut points: Vec<[f64; 3]> = Vec::new();
    // (point indices, VTK cell type, grain, radius)
    let mut cells: Vec<(Vec<usize>, u8, usize, f64)> = Vec::new();
    let pt = |v: SVector<f64, D>| [v[0], v[1], if D == 3 { v[2] } else { 0.0 }];
    for (gi, g) in p.grains.iter().enumerate() {
        match &g.grain.geometry {
            Geometry::Swept(e) => {
                for s in e {
                    let a = points.len();
                    points.push(pt(g.centre + s.a));
                    if s.a == s.b {
                        cells.push((vec![a], 1, gi, s.radius));
                    } else {
                        points.push(pt(g.centre + s.b));
                        cells.push((vec![a, a + 1], 3, gi, s.radius));
                    }
                }
            }
            Geometry::Convex { vertices, shape } => match shape {
                ParryConvex::Polygon(_) => {
                    let a = points.len();
                    points.extend(vertices.iter().map(|v| pt(g.centre + v)));
                    cells.push(((a..a + vertices.len()).collect(), 7, gi, 0.0));
                }
                ParryConvex::Polyhedron(poly) => {
                    let (tv, ti) = poly.to_trimesh();
                    let a = points.len();
                    points
                        .extend(tv.iter().map(|v| {
                            [g.centre[0] + v.x, g.centre[1] + v.y, g.centre[2 % D] + v.z]
                        }));
                    for t in ti {
                        cells.push((t.iter().map(|&k| a + k as usize).collect(), 5, gi, 0.0));
                    }
                }
            },
        }
    }
    writeln!(w, r#"<?xml version="1.0"?>"#)?;
    writeln!(
        w,
        r#"<VTKFile type="UnstructuredGrid" version="1.0" byte_order="LittleEndian" header_type="UInt64">"#
    )?;
    writeln!(w, "<UnstructuredGrid>")?;
    writeln!(
        w,
        r#"<Piece NumberOfPoints="{}" NumberOfCells="{}">"#,
        points.len(),
        cells.len()
    )?;
    writeln!(w, r#"<CellData Scalars="radius">"#)?;
    writeln!(w, r#"<DataArray type="Int64" Name="grain" format="ascii">"#)?;
    for c in &cells {
        writeln!(w, "{}", c.2)?;
    }
    writeln!(w, "</DataArray>")?;
    writeln!(
        w,
        r#"<DataArray type="Float64" Name="radius" format="ascii">"#
    )?;
    for c in &cells {
        writeln!(w, "{:e}", c.3)?;
    }
    writeln!(w, "</DataArray>\n</CellData>\n<Points>")?;
    writeln!(
        w,
        r#"<DataArray type="Float64" NumberOfComponents="3" format="ascii">"#
    )?;
    for q in &points {
        writeln!(w, "{:e} {:e} {:e}", q[0], q[1], q[2])?;
    }
    writeln!(w, "</DataArray>\n</Points>\n<Cells>")?;
    writeln!(
        w,
        r#"<DataArray type="Int64" Name="connectivity" format="ascii">"#
    )?;
    for c in &cells {
        let s: Vec<String> = c.0.iter().map(ToString::to_string).collect();
        writeln!(w, "{}", s.join(" "))?;
    }
    writeln!(w, "</DataArray>")?;
    writeln!(
        w,
        r#"<DataArray type="Int64" Name="offsets" format="ascii">"#
    )?;
    let mut off = 0;
    for c in &cells {
        off += c.0.len();
        writeln!(w, "{off}")?;
    }
    writeln!(w, "</DataArray>")?;
    writeln!(w, r#"<DataArray type="UInt8" Name="types" format="ascii">"#)?;
    for c in &cells {
        writeln!(w, "{}", c.1)?;
    }
    writeln!(
        w,
        "</DataArray>\n</Cells>\n</Piece>\n</UnstructuredGrid>\n</VTKFile>"
    )?;
    Ok(())
}
