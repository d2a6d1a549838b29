//! Writers for packings: CSV, VTU (ParaView), LIGGGHTS/LAMMPS `read_data`,
//! Yade text and SVG. All go through `impl Write`; the library touches no
//! files. 2D disks are written as spheres in the plane `z = 0`.

use crate::domain::{Domain, Shape};
use crate::error::{Error, Result};
use crate::packer::Disk;
use std::io::Write;

fn check(disks: &[Disk]) -> Result<()> {
    for d in disks {
        crate::error::finite("disk x", d.center.x)?;
        crate::error::finite("disk y", d.center.y)?;
        crate::error::positive("disk radius", d.radius)?;
    }
    Ok(())
}

/// CSV with header `id,x,y,radius` (ids from 1).
///
/// # Errors
/// [`Error::NonFinite`]/[`Error::NonPositive`] for a bad disk; [`Error::Io`].
pub fn write_csv(disks: &[Disk], mut w: impl Write) -> Result<()> {
    check(disks)?;
    writeln!(w, "id,x,y,radius")?;
    for (i, d) in disks.iter().enumerate() {
        writeln!(
            w,
            "{},{:e},{:e},{:e}",
            i + 1,
            d.center.x,
            d.center.y,
            d.radius
        )?;
    }
    Ok(())
}

/// VTK XML unstructured grid (`.vtu`, ASCII): one vertex cell per disk and
/// point arrays `radius` and `diameter` (ParaView: Glyph filter, sphere,
/// scale by `diameter`).
///
/// # Errors
/// As [`write_csv`].
pub fn write_vtu(disks: &[Disk], mut w: impl Write) -> Result<()> {
    check(disks)?;
    write_vtu_glyphs(
        disks.len(),
        |i| disks[i].radius,
        |i, w| writeln!(w, "{:e} {:e} 0", disks[i].center.x, disks[i].center.y),
        &mut w,
    )?;
    Ok(())
}

/// A VTU of `n` points with point arrays `radius` and `diameter` (the
/// 2D and 3D sphere writers): `radius(i)`, and `centre(i, w)` writes point
/// `i`'s coordinates line.
///
/// # Errors
/// The writer's I/O error.
pub fn write_vtu_glyphs<W: Write>(
    n: usize,
    radius: impl Fn(usize) -> f64,
    centre: impl Fn(usize, &mut W) -> std::io::Result<()>,
    w: &mut W,
) -> std::io::Result<()> {
    writeln!(w, r#"<?xml version="1.0"?>"#)?;
    writeln!(
        w,
        r#"<VTKFile type="UnstructuredGrid" version="1.0" byte_order="LittleEndian" header_type="UInt64">"#
    )?;
    writeln!(w, "<UnstructuredGrid>")?;
    writeln!(w, r#"<Piece NumberOfPoints="{n}" NumberOfCells="{n}">"#)?;
    writeln!(w, r#"<PointData Scalars="radius">"#)?;
    for (name, f) in [("radius", 1.0), ("diameter", 2.0)] {
        writeln!(
            w,
            r#"<DataArray type="Float64" Name="{name}" format="ascii">"#
        )?;
        for i in 0..n {
            writeln!(w, "{:e}", f * radius(i))?;
        }
        writeln!(w, "</DataArray>")?;
    }
    writeln!(w, "</PointData>")?;
    writeln!(w, "<Points>")?;
    writeln!(
        w,
        r#"<DataArray type="Float64" NumberOfComponents="3" format="ascii">"#
    )?;
    for i in 0..n {
        centre(i, w)?;
    }
    write_vtu_vertex_cells(n, w)
}

/// The end of a VTU of `n` points written as vertex cells: closes the
/// points array, writes connectivity, offsets and types (VTK_VERTEX) and
/// closes the file (shared by the 2D and 3D writers).
fn write_vtu_vertex_cells(n: usize, w: &mut impl Write) -> std::io::Result<()> {
    writeln!(w, "</DataArray>")?;
    writeln!(w, "</Points>")?;
    writeln!(w, "<Cells>")?;
    writeln!(
        w,
        r#"<DataArray type="Int64" Name="connectivity" format="ascii">"#
    )?;
    for i in 0..n {
        writeln!(w, "{i}")?;
    }
    writeln!(w, "</DataArray>")?;
    writeln!(
        w,
        r#"<DataArray type="Int64" Name="offsets" format="ascii">"#
    )?;
    for i in 1..=n {
        writeln!(w, "{i}")?;
    }
    writeln!(w, "</DataArray>")?;
    writeln!(w, r#"<DataArray type="UInt8" Name="types" format="ascii">"#)?;
    for _ in 0..n {
        writeln!(w, "1")?;
    }
    writeln!(w, "</DataArray>")?;
    writeln!(w, "</Cells>")?;
    writeln!(w, "</Piece>")?;
    writeln!(w, "</UnstructuredGrid>")?;
    writeln!(w, "</VTKFile>")?;
    Ok(())
}

/// LIGGGHTS/LAMMPS `read_data` file, `atom_style sphere`
/// (`id type diameter density x y z`), one atom type, box = bounding box
/// of the disks, `z = 0` with a slab of one largest diameter.
///
/// # Errors
/// As [`write_csv`], plus [`Error::NonPositive`] for the density and
/// [`Error::Empty`] for no disks (a box cannot be derived).
pub fn write_lammps_data(disks: &[Disk], density: f64, mut w: impl Write) -> Result<()> {
    check(disks)?;
    crate::error::positive("density", density)?;
    if disks.is_empty() {
        return Err(Error::Empty { what: "disk list" });
    }
    let (mut lo, mut hi, mut dmax) = ([f64::MAX; 2], [f64::MIN; 2], 0.0_f64);
    for d in disks {
        lo[0] = lo[0].min(d.center.x - d.radius);
        lo[1] = lo[1].min(d.center.y - d.radius);
        hi[0] = hi[0].max(d.center.x + d.radius);
        hi[1] = hi[1].max(d.center.y + d.radius);
        dmax = dmax.max(2.0 * d.radius);
    }
    writeln!(
        w,
        "LAMMPS data file written by packer-quadtree (atom_style sphere, 2D disks at z = 0)"
    )?;
    writeln!(w)?;
    writeln!(w, "{} atoms", disks.len())?;
    writeln!(w, "1 atom types")?;
    writeln!(w)?;
    writeln!(w, "{:e} {:e} xlo xhi", lo[0], hi[0])?;
    writeln!(w, "{:e} {:e} ylo yhi", lo[1], hi[1])?;
    writeln!(w, "{:e} {:e} zlo zhi", -dmax, dmax)?;
    writeln!(w)?;
    writeln!(w, "Atoms # sphere")?;
    writeln!(w)?;
    for (i, d) in disks.iter().enumerate() {
        writeln!(
            w,
            "{} 1 {:e} {:e} {:e} {:e} 0",
            i + 1,
            2.0 * d.radius,
            density,
            d.center.x,
            d.center.y
        )?;
    }
    Ok(())
}

/// Yade text for `ymport.text`: one `x y z r` line per disk, `z = 0`.
///
/// # Errors
/// As [`write_csv`].
pub fn write_yade(disks: &[Disk], mut w: impl Write) -> Result<()> {
    check(disks)?;
    writeln!(w, "# x y z r")?;
    for d in disks {
        writeln!(w, "{:e} {:e} 0 {:e}", d.center.x, d.center.y, d.radius)?;
    }
    Ok(())
}

/// SVG picture: the domain outline and the disks (y up).
///
/// # Errors
/// Domain validation errors; as [`write_csv`].
pub fn write_svg(domain: &Domain, disks: &[Disk], mut w: impl Write) -> Result<()> {
    check(disks)?;
    let shape = domain.shape()?;
    let (lo, hi) = shape.bbox();
    let (wd, ht) = (hi[0] - lo[0], hi[1] - lo[1]);
    let m = 0.02 * wd.max(ht);
    let stroke = 0.002 * wd.max(ht);
    writeln!(
        w,
        r#"<svg xmlns="http://www.w3.org/2000/svg" viewBox="{} {} {} {}">"#,
        lo[0] - m,
        -hi[1] - m,
        wd + 2.0 * m,
        ht + 2.0 * m
    )?;
    writeln!(w, r#"<g transform="scale(1,-1)">"#)?;
    match shape {
        Shape::Poly(v) => {
            let pts: Vec<String> = v.iter().map(|p| format!("{},{}", p[0], p[1])).collect();
            writeln!(
                w,
                r#"<polygon points="{}" fill="none" stroke="black" stroke-width="{stroke}"/>"#,
                pts.join(" ")
            )?;
        }
        Shape::Disk { c, r } => {
            writeln!(
                w,
                r#"<circle cx="{}" cy="{}" r="{r}" fill="none" stroke="black" stroke-width="{stroke}"/>"#,
                c[0], c[1]
            )?;
        }
    }
    for d in disks {
        writeln!(
            w,
            r##"<circle cx="{}" cy="{}" r="{}" fill="#c8a165"/>"##,
            d.center.x, d.center.y, d.radius
        )?;
    }
    writeln!(w, "</g>")?;
    writeln!(w, "</svg>")?;
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;
    use nalgebra::Point2;

    fn disks() -> Vec<Disk> {
        vec![
            Disk {
                center: Point2::new(1.0, 1.0),
                radius: 0.5,
            },
            Disk {
                center: Point2::new(2.0, 1.0),
                radius: 0.5,
            },
        ]
    }

    fn text(f: impl FnOnce(&mut Vec<u8>) -> Result<()>) -> String {
        let mut buf = Vec::new();
        f(&mut buf).expect("write");
        String::from_utf8(buf).expect("utf8")
    }

    #[test]
    fn formats_have_expected_rows() {
        let d = disks();
        let csv = text(|b| write_csv(&d, b));
        assert_eq!(csv.lines().count(), 3);
        assert_eq!(csv.lines().nth(2), Some("2,2e0,1e0,5e-1"));
        let yade = text(|b| write_yade(&d, b));
        assert_eq!(yade.lines().nth(1), Some("1e0 1e0 0 5e-1"));
        let lmp = text(|b| write_lammps_data(&d, 2650.0, b));
        assert!(lmp.contains("2 atoms"));
        assert!(lmp.contains("Atoms # sphere"));
        assert_eq!(lmp.lines().last(), Some("2 1 1e0 2.65e3 2e0 1e0 0"));
        let vtu = text(|b| write_vtu(&d, b));
        assert!(vtu.contains(r#"NumberOfPoints="2" NumberOfCells="2""#));
        assert_eq!(vtu.matches("<DataArray").count(), 6);
        let svg = text(|b| {
            write_svg(
                &Domain::Rectangle {
                    width: 3.0,
                    height: 2.0,
                },
                &d,
                b,
            )
        });
        assert_eq!(svg.matches("<circle").count(), 2);
    }

    #[test]
    fn bad_disks_are_rejected() {
        let bad = [Disk {
            center: Point2::new(f64::NAN, 0.0),
            radius: 1.0,
        }];
        assert!(write_csv(&bad, Vec::new()).is_err());
        assert!(write_lammps_data(&[], 1.0, Vec::new()).is_err());
        assert!(write_lammps_data(&disks(), -1.0, Vec::new()).is_err());
    }
}
