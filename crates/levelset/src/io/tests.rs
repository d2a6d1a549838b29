//! Round-trip, malformed-input and property tests of the readers and writers.

use super::*;
use crate::error::Error;
use crate::grid::{Grid, GridSpec};
use crate::shapes::Sphere;
use approx::assert_abs_diff_eq;
use nalgebra::{Isometry3, Point3};
use proptest::prelude::*;

fn small_grid() -> Grid {
    let spec = GridSpec {
        dims: [7, 6, 5],
        origin: Point3::new(-0.7, -0.61, -0.5),
        spacing: 0.23,
    };
    Grid::from_shape(spec, &Sphere::new(0.5).expect("s"), &Isometry3::identity()).expect("g")
}

fn assert_grids_identical(a: &Grid, b: &Grid) {
    assert_eq!(a.dims(), b.dims());
    assert_abs_diff_eq!(a.spacing(), b.spacing(), epsilon = 0.0);
    for ax in 0..3 {
        assert_abs_diff_eq!(a.origin()[ax], b.origin()[ax], epsilon = 0.0);
    }
    for (x, y) in a.values().iter().zip(b.values()) {
        assert_abs_diff_eq!(*x, *y, epsilon = 0.0);
    }
}

#[test]
fn lammps_round_trip_is_exact() {
    let g = small_grid();
    let mut buf = Vec::new();
    write_lammps(&mut buf, "grain 7\nsecond line", &g).expect("write");
    let (c, back) = read_lammps(buf.as_slice()).expect("read");
    assert_eq!(c, "grain 7 second line");
    assert_grids_identical(&g, &back);
    let text = String::from_utf8(buf).expect("utf8");
    let lines: Vec<&str> = text.lines().collect();
    assert_eq!(lines[1], "7 6 5");
    assert_eq!(lines.len(), 4 + 7 * 6 * 5);
}

#[test]
fn vtk_round_trip_is_exact() {
    let g = small_grid();
    let mut buf = Vec::new();
    write_vtk(&mut buf, "sphere", &g).expect("write");
    let (title, back) = read_vtk(buf.as_slice()).expect("read");
    assert_eq!(title, "sphere");
    assert_grids_identical(&g, &back);
}

#[test]
fn morph_round_trip_is_exact_and_from_grid_is_consistent() {
    let spec = GridSpec::cube(25, -1.2, 1.2).expect("spec");
    let g =
        Grid::from_shape(spec, &Sphere::new(1.0).expect("s"), &Isometry3::identity()).expect("g");
    let m = MorphFile::from_grid(&g, 2.0, 50).expect("morph");
    let h = spec.spacing;
    // Centre of mass at the grid centre (node 12) in grid units.
    assert_abs_diff_eq!(m.centroid.x, 12.0, epsilon = 1e-6);
    assert_abs_diff_eq!(m.bounding_radius, 1.0 / h, epsilon = 0.02 / h);
    let mut buf = Vec::new();
    write_morph(&mut buf, &m).expect("write");
    let back = read_morph(buf.as_slice()).expect("read");
    assert_abs_diff_eq!(back.mass, m.mass, epsilon = 0.0);
    assert_eq!(back.points.len(), 50);
    for (p, q) in back.points.iter().zip(&m.points) {
        assert_abs_diff_eq!((p - q).norm(), 0.0, epsilon = 0.0);
    }
    assert_grids_identical(&m.grid, &back.grid);
    let text = String::from_utf8(buf).expect("utf8");
    assert_eq!(text.lines().count(), 8, "one field per line");
}

#[test]
fn stl_round_trips() {
    let spec = GridSpec::cube(15, -1.2, 1.2).expect("spec");
    let g =
        Grid::from_shape(spec, &Sphere::new(1.0).expect("s"), &Isometry3::identity()).expect("g");
    let mesh = g.marching_cubes();
    let mut buf = Vec::new();
    write_stl_ascii(&mut buf, "grain", &mesh).expect("write");
    let back = read_stl(buf.as_slice()).expect("read ascii");
    assert_eq!(back.triangles().len(), mesh.triangles().len());
    assert_eq!(back.vertices().len(), mesh.vertices().len());
    assert_abs_diff_eq!(back.signed_volume(), mesh.signed_volume(), epsilon = 1e-12);
    back.check_closed().expect("still closed after welding");
    let mut bin = Vec::new();
    write_stl_binary(&mut bin, &mesh).expect("write");
    assert_eq!(bin.len(), 84 + 50 * mesh.triangles().len());
    let back = read_stl(bin.as_slice()).expect("read binary");
    assert_eq!(back.triangles().len(), mesh.triangles().len());
    assert_abs_diff_eq!(back.signed_volume(), mesh.signed_volume(), epsilon = 1e-5);
    back.check_closed().expect("closed");
}

fn parse_line(e: Error) -> usize {
    match e {
        Error::Parse { line, .. } => line,
        other => panic!("expected a parse error, got {other:?}"),
    }
}

#[test]
fn malformed_files_report_the_line() {
    let bad = "# c\n3 3 3\n0.5\n0 0 0\n1\n2\nx\n";
    assert_eq!(parse_line(read_lammps(bad.as_bytes()).expect_err("bad")), 7);
    let bad = "# c\n3 3 3\n-0.5\n0 0 0\n";
    assert_eq!(parse_line(read_lammps(bad.as_bytes()).expect_err("bad")), 3);
    let bad = "# c\n3 2 3\n0.5\n0 0 0\n";
    assert_eq!(parse_line(read_lammps(bad.as_bytes()).expect_err("bad")), 2);
    let truncated = "# c\n3 3 3\n0.5\n0 0 0\n1\n2\n";
    assert_eq!(
        parse_line(read_lammps(truncated.as_bytes()).expect_err("bad")),
        6
    );
    let nan = "# c\n3 3 3\n0.5\n0 0 0\nNaN\n";
    assert_eq!(parse_line(read_lammps(nan.as_bytes()).expect_err("bad")), 5);
    let vtk = "# vtk DataFile Version 3.0\nt\nASCII\nDATASET STRUCTURED_POINTS\n\
               DIMENSIONS 3 3 3\nORIGIN 0 0 0\nSPACING 1 2 1\n";
    assert_eq!(parse_line(read_vtk(vtk.as_bytes()).expect_err("bad")), 7);
    let vtk = "# vtk DataFile Version 3.0\nt\nBINARY\n";
    assert_eq!(parse_line(read_vtk(vtk.as_bytes()).expect_err("bad")), 3);
    let morph = "1\n1 1 1\n0 0 0\n2\n0 0 0 1 1\n";
    assert_eq!(
        parse_line(read_morph(morph.as_bytes()).expect_err("bad")),
        5
    );
    let stl = "solid x\nfacet normal 0 0 1\nouter loop\nvertex 0 0 0\nvertex 1 0 0\nvertex 0 1\n";
    assert_eq!(parse_line(read_stl(stl.as_bytes()).expect_err("bad")), 6);
    assert!(matches!(
        read_stl(&b"garbage"[..]),
        Err(Error::Parse { .. })
    ));
    assert!(matches!(
        read_lammps(&b"# c\n\xff\xfe\n"[..]),
        Err(Error::Parse { line: 2, .. })
    ));
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 256, ..ProptestConfig::default() })]

    #[test]
    fn readers_never_panic_on_arbitrary_bytes(data in proptest::collection::vec(any::<u8>(), 0..400)) {
        for r in [read_lammps(data.as_slice()).err(), read_vtk(data.as_slice()).err(),
                  read_morph(data.as_slice()).err()] {
            if let Some(Error::Parse { line, .. }) = r {
                prop_assert!(line >= 1);
            }
        }
        let _ = read_stl(data.as_slice());
    }

    #[test]
    fn truncated_files_never_panic(cut in 0usize..4000, which in 0usize..4) {
        let g = small_grid();
        let mut buf = Vec::new();
        match which {
            0 => write_lammps(&mut buf, "c", &g).expect("w"),
            1 => write_vtk(&mut buf, "c", &g).expect("w"),
            2 => write_stl_ascii(&mut buf, "c", &g.marching_cubes()).expect("w"),
            _ => write_stl_binary(&mut buf, &g.marching_cubes()).expect("w"),
        }
        let cut = cut.min(buf.len());
        let part = &buf[..cut];
        let res = match which {
            0 => read_lammps(part).map(|_| ()),
            1 => read_vtk(part).map(|_| ()),
            _ => read_stl(part).map(|_| ()),
        };
        // A cut that removes the whole last line (values or `endsolid`) must fail; a cut
        // inside the last number can still parse (as a shorter number).
        let body = &buf[..buf.len() - 1];
        let last_line_start = body.iter().rposition(|&b| b == b'\n').map_or(0, |i| i + 1);
        if cut < last_line_start && which != 3 {
            prop_assert!(res.is_err());
        }
        if which == 3 && cut < buf.len() {
            prop_assert!(res.is_err());
        }
    }

    #[test]
    fn mutated_lammps_files_never_panic(pos in 0usize..2000, byte in any::<u8>()) {
        let g = small_grid();
        let mut buf = Vec::new();
        write_lammps(&mut buf, "c", &g).expect("w");
        let p = pos.min(buf.len() - 1);
        buf[p] = byte;
        let _ = read_lammps(buf.as_slice());
        let _ = read_vtk(buf.as_slice());
        let _ = read_morph(buf.as_slice());
    }
}

mod labels;
