//! Round-trip, malformed-input and property tests of the readers and writers.

use super::*;
use crate::error::Error;
use crate::grid::{Grid, GridSpec};
use crate::mesh::tests::{cube_mesh, icosphere, tetrahedron};
use crate::mesh::{Orientation, TriMesh};
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

/// Fixed-decimal morph files: every value within half a unit of the last decimal, the
/// mass and moments exact, smaller than the round-trip file; bad decimals and huge values
/// are errors.
#[test]
fn morph_fixed_decimals_round_trip_within_half_an_ulp_of_the_last_digit() {
    let spec = GridSpec::cube(25, -1.2, 1.2).expect("spec");
    let g =
        Grid::from_shape(spec, &Sphere::new(1.0).expect("s"), &Isometry3::identity()).expect("g");
    let m = MorphFile::from_grid(&g, 2.0, 50).expect("morph");
    let mut exact = Vec::new();
    write_morph(&mut exact, &m).expect("write");
    for decimals in [0u32, 3, 9] {
        let mut buf = Vec::new();
        write_morph_decimals(&mut buf, &m, decimals).expect("write");
        let back = read_morph(buf.as_slice()).expect("read");
        let tol = 0.5 * 10f64.powi(-(decimals as i32)) * (1.0 + 1e-9);
        assert_abs_diff_eq!(back.mass, m.mass, epsilon = 0.0);
        for (a, b) in back.grid.values().iter().zip(m.grid.values()) {
            assert!((a - b).abs() <= tol, "{a} {b} at {decimals}");
        }
        for (p, q) in back.points.iter().zip(&m.points) {
            assert!((p - q).amax() <= tol);
        }
        assert!(buf.len() < exact.len());
    }
    // negative values keep their sign below one unit
    let mut buf = Vec::new();
    write_morph_decimals(&mut buf, &m, 9).expect("write");
    assert!(String::from_utf8(buf).expect("utf8").contains(" -0."));
    assert!(write_morph_decimals(Vec::new(), &m, 13).is_err());
    let mut huge = m.clone();
    huge.points[0].x = 1e30;
    assert!(write_morph_decimals(Vec::new(), &huge, 9).is_err());
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

#[test]
fn obj_round_trip_is_exact() {
    for m in [tetrahedron(), cube_mesh(), icosphere(2)] {
        let mut buf = Vec::new();
        write_obj(&mut buf, &m).expect("write");
        let back = read_obj(buf.as_slice()).expect("read");
        assert_eq!(back.triangles(), m.triangles());
        assert_eq!(back.vertices().len(), m.vertices().len());
        for (p, q) in back.vertices().iter().zip(m.vertices()) {
            assert_abs_diff_eq!((p - q).norm(), 0.0, epsilon = 0.0);
        }
    }
}

/// The unit cube [0, 1]³ as six quads in every corner syntax, with relative indices,
/// comments, groups, a continuation line, CRLF and vertex colours.
const CUBE_QUADS: &str = "# a cube\r\nmtllib cube.mtl\r\no cube\r\n\
    v 0 0 0\r\nv 1 0 0\r\nv 1 1 0\r\nv 0 1 0 1.0\r\n\
    v 0 0 1 0.5 0.5 0.5\r\nv 1 0 1\r\nv 1.0e0 1E0 1\r\nv 0 1 \\\r\n 1\r\n\
    vt 0 0\nvt 1 0\nvt 1 1\nvn 0 0 1\ng sides\ns off\nusemtl stone\n\
    f 1 4 3 2 # bottom, −z\n\
    f 5/1 6/2 7/3 8/1\n\
    f 1//1 2//1 6//1 5//1\n\
    f 4/1/1 8/2/1 7/3/1 3/1/1\n\
    f -8 -4 -1 -5\n\
    f -7 -6 -2 -3\n\
    l 1 2\np 3\n";

#[test]
fn obj_quads_relative_indices_and_every_corner_form() {
    let m = read_obj(CUBE_QUADS.as_bytes()).expect("read");
    assert_eq!(m.vertices().len(), 8);
    assert_eq!(m.triangles().len(), 12);
    // Fan triangulation from the first corner.
    assert_eq!(m.triangles()[0], [0, 3, 2]);
    assert_eq!(m.triangles()[1], [0, 2, 1]);
    assert_eq!(m.triangles()[8], [0, 4, 7]);
    m.check_closed().expect("closed and consistent");
    assert_abs_diff_eq!(m.signed_volume(), 1.0, epsilon = 1e-15);
    let (p, r) = m.prepare_closed(Orientation::Refuse).expect("a grain");
    assert_eq!(r, crate::mesh::MeshRepair::default());
    assert_abs_diff_eq!(p.centroid().expect("c").x, 0.5, epsilon = 1e-15);
    // Faces may refer to vertices defined later.
    let forward = "f 1 3 2\nf 1 2 4\nf 1 4 3\nf 2 3 4\nv 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 0 1\n";
    let t = read_obj(forward.as_bytes()).expect("forward references");
    assert_abs_diff_eq!(t.signed_volume(), 1.0 / 6.0, epsilon = 1e-15);
}

#[test]
fn obj_seams_are_welded_by_prepare_closed() {
    // Vertex 9 repeats vertex 1 (as a UV seam would); the reader keeps the file numbering.
    let text = "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 0 1\nv 0 0 0\nf 1 3 2\nf 5 2 4\nf 1 4 3\nf 2 3 4\n";
    let m = read_obj(text.as_bytes()).expect("read");
    assert_eq!(m.vertices().len(), 5);
    assert!(m.check_closed().is_err());
    let (p, r) = m
        .prepare_closed(Orientation::Refuse)
        .expect("closed once welded");
    assert_eq!((r.welded, p.vertices().len()), (1, 4));
}

fn obj_error(text: &str) -> (usize, String) {
    match read_obj(text.as_bytes()) {
        Err(Error::Parse {
            format: "obj",
            line,
            reason,
        }) => (line, reason),
        other => panic!("expected an OBJ parse error for {text:?}, got {other:?}"),
    }
}

#[test]
fn malformed_obj_reports_the_line() {
    let v = "v 0 0 0\nv 1 0 0\nv 0 1 0\n";
    let cases = [
        (format!("{v}f 1 2 4\n"), 4, "defines 3 vertices"),
        (
            format!("{v}f 1 2 3\n# c\nf 1 2 7\nv 0 0 1\n"),
            6,
            "defines 4 vertices",
        ),
        (format!("{v}f -1 -2 -4\n"), 4, "relative vertex index -4"),
        (format!("f -1 -2 -3\n{v}"), 1, "relative"),
        (format!("{v}f 0 1 2\n"), 4, "index 0"),
        (format!("{v}f 1 2\n"), 4, "at least 3"),
        (format!("{v}f 1 2 x\n"), 4, "vertex index"),
        (format!("{v}f 1 2 3/1/1/1\n"), 4, "more than three"),
        (format!("{v}f 1 2 3/a\n"), 4, "texture or normal"),
        (
            format!("{v}f 1 2 99999999999999999999\n"),
            4,
            "vertex index",
        ),
        (format!("v 0 0 0\nv 1 nan 0\n{v}f 1 2 3\n"), 2, "not finite"),
        (format!("v 0 0 inf\n{v}f 1 2 3\n"), 1, "not finite"),
        (format!("v 0 0\n{v}f 1 2 3\n"), 1, "3 coordinates"),
        (
            format!("v 0 0 0 1 2 3 4 5\n{v}f 1 2 3\n"),
            1,
            "3 coordinates",
        ),
        ("v 0 0 x\n".to_string(), 1, "number"),
        (v.to_string(), 3, "no faces"),
        (String::new(), 1, "no faces"),
        (format!("{v}curv 0 1 1 2\n"), 4, "free-form"),
        (format!("{v}frobnicate\n"), 4, "unknown statement"),
        (format!("{v}f 1 2 \\\n3 9\n"), 4, "defines 3 vertices"),
    ];
    for (text, line, what) in cases {
        let (l, reason) = obj_error(&text);
        assert_eq!(l, line, "{text:?}: {reason}");
        assert!(reason.contains(what), "{text:?}: {reason}");
    }
    // Names in other encodings are harmless; a broken number is not.
    let latin1 = b"# cr\xe9\xe9\no pi\xe8ce\nv 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n";
    assert!(read_obj(&latin1[..]).is_ok());
    let (l, _) = match read_obj(&b"v 0 0 0\nv 1 \xff 0\n"[..]) {
        Err(Error::Parse { line, reason, .. }) => (line, reason),
        other => panic!("{other:?}"),
    };
    assert_eq!(l, 2);
}

/// The binary STL of `mesh` with the header overwritten by `header`.
fn binary_with_header(mesh: &TriMesh, header: &[u8]) -> Vec<u8> {
    let mut bin = Vec::new();
    write_stl_binary(&mut bin, mesh).expect("write");
    bin[..80].fill(b' ');
    bin[..header.len()].copy_from_slice(header);
    bin
}

#[test]
fn binary_stl_whose_header_says_solid_is_read_as_binary() {
    let m = icosphere(1);
    let bin = binary_with_header(&m, b"solid ico exported by a CAD package");
    let back = read_stl(bin.as_slice()).expect("binary despite 'solid'");
    assert_eq!(back.triangles().len(), 80);
    assert_eq!(back.vertices().len(), 42);
    back.check_closed().expect("closed");
    // The same file with a stray trailing byte is neither: the error says why.
    let mut bad = bin.clone();
    bad.push(0);
    match read_stl(bad.as_slice()) {
        Err(Error::Parse { reason, .. }) => {
            assert!(reason.contains("not binary STL"), "{reason}");
            assert!(reason.contains(&format!("size {}", bad.len())), "{reason}");
        }
        other => panic!("expected a parse error, got {other:?}"),
    }
    // Short files of any content do not panic.
    for n in 0..90 {
        let _ = read_stl(&bin[..n.min(bin.len())]);
    }
    let empty = binary_with_header(&m, b"solid")[..84]
        .iter()
        .enumerate()
        .map(|(i, &b)| if i >= 80 { 0 } else { b })
        .collect::<Vec<u8>>();
    assert!(matches!(
        read_stl(empty.as_slice()),
        Err(Error::Parse { .. })
    ));
}

#[test]
fn ascii_stl_variants() {
    let tet = tetrahedron();
    let mut buf = Vec::new();
    write_stl_ascii(&mut buf, "tet", &tet).expect("write");
    let text = String::from_utf8(buf).expect("utf8");
    // CRLF, a several-word name, `endsolid name`, scientific notation, `nan` normals.
    let mut lines: Vec<String> = text.lines().map(str::to_string).collect();
    lines[0] = "solid my tet grain".to_string();
    lines[1] = "  facet normal nan -nan NaN".to_string();
    let crlf =
        (lines.join("\r\n") + "\r\n").replacen("vertex 1 1 1", "vertex 1.0E+00 10e-1 0.1e1", 1);
    assert!(crlf.contains("endsolid tet\r\n") && crlf.contains("1.0E+00"));
    let m = read_stl(crlf.as_bytes()).expect("variants");
    assert_eq!(m.triangles().len(), 4);
    assert_eq!(m.vertices().len(), 4);
    m.check_closed().expect("closed");
    assert_abs_diff_eq!(m.signed_volume(), tet.signed_volume(), epsilon = 1e-15);
    // A name in Latin-1 is harmless.
    let latin1 = [
        b"solid pi\xe8ce\n".as_slice(),
        text.split_once('\n').expect("l").1.as_bytes(),
    ]
    .concat();
    assert_eq!(
        read_stl(latin1.as_slice())
            .expect("latin-1 name")
            .triangles()
            .len(),
        4
    );
    // Two solids in one file are concatenated (and are then two components).
    let two = format!("{text}{}", text.replace("solid tet", "solid other"));
    let m2 = read_stl(two.as_bytes()).expect("two solids");
    assert_eq!(m2.triangles().len(), 8);
    // Trailing data after `endsolid` is an error naming its line.
    let trailing = format!("{text}garbage\n");
    assert!(matches!(
        read_stl(trailing.as_bytes()),
        Err(Error::Parse { line: 31, .. })
    ));
    // −0 welds with 0; a degenerate facet is kept for prepare_closed.
    let corner = TriMesh::new(
        vec![
            Point3::new(0.0, 0.0, 0.0),
            Point3::new(1.0, 0.0, 0.0),
            Point3::new(0.0, 1.0, 0.0),
            Point3::new(0.0, 0.0, 1.0),
        ],
        vec![[0, 2, 1], [0, 1, 3], [0, 3, 2], [1, 2, 3]],
    )
    .expect("valid");
    let mut buf = Vec::new();
    write_stl_ascii(&mut buf, "", &corner).expect("write");
    let text = String::from_utf8(buf)
        .expect("utf8")
        .replacen("vertex 0 0 0", "vertex -0 0 -0.0e0", 1)
        .replace(
            "endsolid",
            "facet normal 0 0 0\nouter loop\nvertex 1 0 0\nvertex 1 0 0\nvertex 0 1 0\n\
             endloop\nendfacet\nendsolid",
        );
    let m = read_stl(text.as_bytes()).expect("read");
    assert_eq!((m.vertices().len(), m.triangles().len()), (4, 5));
    let (p, r) = m.prepare_closed(Orientation::Refuse).expect("a grain");
    assert_eq!((r.degenerate_removed, p.triangles().len()), (1, 4));
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
        if let Err(Error::Parse { line, .. }) = read_obj(data.as_slice()) {
            prop_assert!(line >= 1);
        }
    }

    /// Token soups near the OBJ grammar reach deep into the parser.
    #[test]
    fn obj_reader_never_panics_on_token_soup(
        parts in proptest::collection::vec(proptest::sample::select(vec![
            "v", "f", "vt", "o", " ", "  ", "\n", "\r\n", "\\", "#", "/", "//", "1", "2", "3",
            "-1", "-3", "0", "0.5", "1e308", "1e309", "nan", "-", "99999999999999999999",
        ]), 0..120),
    ) {
        let text: String = parts.concat();
        match read_obj(text.as_bytes()) {
            Ok(m) => {
                let _ = m.prepare_closed(Orientation::Repair);
                let _ = m.centroid();
            }
            Err(Error::Parse { line, .. }) => prop_assert!(line >= 1),
            Err(e) => prop_assert!(false, "unexpected error {e:?}"),
        }
    }

    #[test]
    fn truncated_and_mutated_meshes_never_panic(
        cut in 0usize..6000,
        pos in 0usize..6000,
        byte in any::<u8>(),
        which in 0usize..3,
    ) {
        let m = icosphere(1);
        let mut buf = Vec::new();
        match which {
            0 => write_obj(&mut buf, &m).expect("w"),
            1 => write_stl_ascii(&mut buf, "ico", &m).expect("w"),
            _ => write_stl_binary(&mut buf, &m).expect("w"),
        }
        let read = |data: &[u8]| match which {
            0 => read_obj(data),
            _ => read_stl(data),
        };
        let full = buf.len();
        let part = &buf[..cut.min(full)];
        // A truncated file never becomes a closed grain: what survives has a hole (the
        // triangle closing it is exactly the lost one). Only the final line break of OBJ and
        // the name after `endsolid` may be lost harmlessly.
        let harmless = match which {
            0 => full - 1,
            1 => buf.windows(8).rposition(|w| w == b"endsolid").map_or(full, |i| i + 8),
            _ => full,
        };
        let prepared = read(part).and_then(|mesh| mesh.prepare_closed(Orientation::Refuse));
        prop_assert_eq!(prepared.is_ok(), cut >= harmless);
        let mut mutated = buf.clone();
        mutated[pos % full] = byte;
        if let Ok(mesh) = read(&mutated)
            && let Ok((p, _)) = mesh.prepare_closed(Orientation::Repair)
        {
            p.check_closed().expect("prepared meshes are closed");
        }
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
