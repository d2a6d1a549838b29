//! Tests of the 3D packing formats: bit-exact round trips, the LAMMPS box,
//! validation before writing, parse errors with line numbers, and readers
//! that never panic.

use super::*;
use nalgebra::Vector3;
use proptest::prelude::*;
use rand::{Rng, SeedableRng};

/// `n` spheres with full-mantissa coordinates in `[-50, 50)³` and radii in
/// `[0.01, 2)` (overlaps do not matter to the formats).
fn random_spheres(n: usize, seed: u64) -> Vec<Sphere> {
    println!("random_spheres seed {seed}");
    let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(seed);
    (0..n)
        .map(|_| Sphere {
            center: Point3::new(
                rng.random_range(-50.0..50.0),
                rng.random_range(-50.0..50.0),
                rng.random_range(-50.0..50.0),
            ),
            radius: rng.random_range(0.01..2.0),
        })
        .collect()
}

/// `nx · ny · nz` spheres of radius 0.45 on the unit simple cubic lattice
/// (centres at half-integers) in the box `[0, n]`: non-overlapping, inside.
fn lattice(nx: usize, ny: usize, nz: usize, periodic: [bool; 2]) -> (Vec<Sphere>, Container) {
    let mut spheres = Vec::new();
    for k in 0..nz {
        for j in 0..ny {
            for i in 0..nx {
                spheres.push(Sphere {
                    center: Point3::new(i as f64 + 0.5, j as f64 + 0.5, k as f64 + 0.5),
                    radius: 0.45,
                });
            }
        }
    }
    let container = Container::Box {
        min: Point3::origin(),
        max: Point3::new(nx as f64, ny as f64, nz as f64),
        periodic,
    };
    (spheres, container)
}

fn bytes(f: impl FnOnce(&mut Vec<u8>) -> Result<()>) -> Vec<u8> {
    let mut buf = Vec::new();
    f(&mut buf).expect("write");
    buf
}

/// Bit-for-bit equality of two sphere lists (`-0.0 ≠ 0.0` here).
fn assert_identical(a: &[Sphere], b: &[Sphere]) {
    assert_eq!(a.len(), b.len());
    for (i, (s, t)) in a.iter().zip(b).enumerate() {
        for k in 0..3 {
            assert_eq!(
                s.center[k].to_bits(),
                t.center[k].to_bits(),
                "sphere {i} coordinate {k}: {} vs {}",
                s.center[k],
                t.center[k]
            );
        }
        assert_eq!(s.radius.to_bits(), t.radius.to_bits(), "sphere {i} radius");
    }
}

/// The `line` of an [`Error::Parse`], or a panic with the error.
fn parse_line(e: Result<impl std::fmt::Debug>) -> usize {
    match e {
        Err(Error::Parse { line, .. }) => line,
        other => panic!("expected a parse error, got {other:?}"),
    }
}

#[test]
fn every_format_round_trips_bit_for_bit() {
    let spheres = random_spheres(200, 7);
    let csv = bytes(|b| write_csv3(&spheres, b));
    assert_identical(&read_csv3(csv.as_slice()).expect("csv"), &spheres);
    let yade = bytes(|b| write_yade3(&spheres, b));
    assert_identical(&read_yade3(yade.as_slice()).expect("yade"), &spheres);
    let vtu = bytes(|b| write_vtu3(&spheres, b));
    assert_identical(&read_vtu3(vtu.as_slice()).expect("vtu"), &spheres);
    for periodic in [[false; 2], [true; 2], [true, false]] {
        let container = Container::Box {
            min: Point3::new(-50.0, -50.0, -50.0),
            max: Point3::new(50.0, 50.0, 50.0),
            periodic,
        };
        let lmp = bytes(|b| write_lammps_data3(&spheres, &container, 2650.0, b));
        let data = read_lammps_data3(lmp.as_slice()).expect("lammps");
        assert_identical(&data.spheres, &spheres);
        assert_eq!(data.ids, (1..=200).collect::<Vec<u64>>());
        assert!(
            data.densities
                .iter()
                .all(|d| d.to_bits() == 2650.0_f64.to_bits())
        );
    }
}

#[test]
fn extreme_values_round_trip() {
    let spheres = vec![
        Sphere {
            center: Point3::new(-0.0, f64::MIN_POSITIVE, 5e-324),
            radius: 5e-324,
        },
        Sphere {
            center: Point3::new(f64::MAX, -f64::MAX, 0.1 + 0.2),
            radius: f64::MAX,
        },
        Sphere {
            center: Point3::new(1.0 / 3.0, -1e-300, 123456789.0),
            radius: f64::MAX / 2.0,
        },
    ];
    let csv = bytes(|b| write_csv3(&spheres, b));
    assert_identical(&read_csv3(csv.as_slice()).expect("csv"), &spheres);
    let yade = bytes(|b| write_yade3(&spheres, b));
    assert_identical(&read_yade3(yade.as_slice()).expect("yade"), &spheres);
    // Diameters of radius f64::MAX overflow: the diameter formats refuse.
    assert!(matches!(
        write_vtu3(&spheres, Vec::new()),
        Err(Error::NonPositive { .. } | Error::NonFinite { .. })
    ));
    let vtu = bytes(|b| write_vtu3(&spheres[2..], b));
    assert_identical(&read_vtu3(vtu.as_slice()).expect("vtu"), &spheres[2..]);
}

#[test]
fn lammps_header_and_box() {
    let (spheres, container) = lattice(2, 2, 1, [false; 2]);
    let text = String::from_utf8(bytes(|b| {
        write_lammps_data3(&spheres, &container, 2650.0, b)
    }))
    .expect("utf8");
    let lines: Vec<&str> = text.lines().collect();
    assert!(lines[0].contains("boundary f f f"));
    assert_eq!(lines[2], "4 atoms");
    assert_eq!(lines[3], "1 atom types");
    assert_eq!(lines[5], "0e0 2e0 xlo xhi");
    assert_eq!(lines[6], "0e0 2e0 ylo yhi");
    assert_eq!(lines[7], "0e0 1e0 zlo zhi");
    assert_eq!(lines[9], "Atoms # sphere");
    assert_eq!(lines[11], "1 1 9e-1 2.65e3 5e-1 5e-1 5e-1");
    assert_eq!(lines.len(), 15);

    let (spheres, container) = lattice(2, 2, 1, [true, true]);
    let text = String::from_utf8(bytes(|b| write_lammps_data3(&spheres, &container, 1.0, b)))
        .expect("utf8");
    assert!(
        text.lines()
            .next()
            .expect("title")
            .contains("boundary p p f")
    );
}

#[test]
fn lammps_box_is_exact_when_periodic_and_widened_otherwise() {
    // Spheres poking out of the box on every side.
    let spheres = vec![
        Sphere {
            center: Point3::new(-0.5, 0.5, 0.5),
            radius: 1.0,
        },
        Sphere {
            center: Point3::new(10.2, 9.9, 4.8),
            radius: 0.5,
        },
    ];
    let size = Vector3::new(10.0, 10.0, 5.0);
    let walled = Container::walled_box(size);
    let periodic = Container::Box {
        min: Point3::origin(),
        max: Point3::from(size),
        periodic: [true, true],
    };
    let b = read_lammps_data3(bytes(|w| write_lammps_data3(&spheres, &walled, 1.0, w)).as_slice())
        .expect("walled")
        .bounds;
    assert_eq!(b, [[-1.5, 10.7], [-0.5, 10.4], [-0.5, 5.3]]);
    let b =
        read_lammps_data3(bytes(|w| write_lammps_data3(&spheres, &periodic, 1.0, w)).as_slice())
            .expect("periodic")
            .bounds;
    assert_eq!(b, [[0.0, 10.0], [0.0, 10.0], [-0.5, 5.3]]);

    // A radius below half an ulp of its centre still gets a box that holds
    // the centre strictly inside.
    let tiny = [Sphere {
        center: Point3::new(1e10, 1e10, 1e10),
        radius: 1e-10,
    }];
    let b = read_lammps_data3(bytes(|w| write_lammps_data3(&tiny, &walled, 1.0, w)).as_slice())
        .expect("tiny")
        .bounds;
    for bk in b {
        assert!(bk[0] < 1e10 && 1e10 < bk[1]);
    }
}

#[test]
fn cylinder_and_lattice_boxes_hold_every_atom() {
    let (spheres, container) = lattice(10, 10, 5, [false; 2]);
    assert_eq!(spheres.len(), 500);
    for (c, per) in [
        (container, [false; 2]),
        (Container::triaxial(10.0), [false; 2]),
        (lattice(10, 10, 5, [true; 2]).1, [true; 2]),
    ] {
        let data =
            read_lammps_data3(bytes(|w| write_lammps_data3(&spheres, &c, 2650.0, w)).as_slice())
                .expect("read");
        let (lo, hi) = c.bbox();
        for k in 0..3 {
            let b = data.bounds[k];
            if k < 2 && per[k] {
                assert_eq!(b, [lo[k], hi[k]]);
            }
            assert!(b[0] <= lo[k] && hi[k] <= b[1]);
            for s in &spheres {
                assert!(b[0] <= s.center[k] - s.radius && s.center[k] + s.radius <= b[1]);
            }
        }
    }
}

#[test]
fn lammps_reader_takes_foreign_files() {
    let text = "LAMMPS data file via write_data, version 2Aug2023, timestep = 1000\r\n\
                \r\n\
                3 atoms\r\n\
                2 atom types\r\n\
                0 extra bond per atom\r\n\
                \r\n\
                -1.0 1.0 xlo xhi # comment\r\n\
                -2 2 ylo yhi\r\n\
                0 3 zlo zhi\r\n\
                \r\n\
                Masses\r\n\
                \r\n\
                1 1.0\r\n\
                2 2.0\r\n\
                \r\n\
                Atoms\r\n\
                \r\n\
                3 2 0.2 1000 0.5 0.5 2.5 0 0 0\r\n\
                1 1 0.4 2000 -0.5 -1.5 0.5 1 -1 0\r\n\
                \r\n\
                2 1 0.2 1000 0 0 1.5\r\n\
                \r\n\
                Velocities\r\n\
                \r\n\
                1 0 0 0 0 0 0\r\n\
                2 0 0 0 0 0 0\r\n\
                3 0 0 0 0 0 0\r\n";
    let data = read_lammps_data3(text.as_bytes()).expect("read");
    assert_eq!(data.ids, vec![1, 2, 3]);
    assert_eq!(data.bounds, [[-1.0, 1.0], [-2.0, 2.0], [0.0, 3.0]]);
    assert_eq!(data.densities, vec![2000.0, 1000.0, 1000.0]);
    assert_eq!(
        data.spheres[0],
        Sphere {
            center: Point3::new(-0.5, -1.5, 0.5),
            radius: 0.2
        }
    );
    assert_eq!(data.spheres[2].center, Point3::new(0.5, 0.5, 2.5));
    // No box lines: LAMMPS's default box.
    let data = read_lammps_data3("t\n1 atoms\nAtoms # sphere\n1 1 1 1 0 0 0\n".as_bytes())
        .expect("default box");
    assert_eq!(data.bounds, [[-0.5, 0.5]; 3]);
    // LIGGGHTS names the style `granular`.
    let data = read_lammps_data3("t\n1 atoms\nAtoms # granular\n1 1 1 1 0 0 0\n".as_bytes())
        .expect("granular");
    assert_eq!(data.spheres.len(), 1);
    // No atoms at all.
    let data = read_lammps_data3("t\n0 atoms\n".as_bytes()).expect("no atoms");
    assert!(data.spheres.is_empty());
}

#[test]
fn writers_validate_before_writing() {
    let good = random_spheres(3, 1);
    let container = Container::walled_box(Vector3::new(1.0, 1.0, 1.0));
    let mut nan_radius = good.clone();
    nan_radius[2].radius = f64::NAN;
    let mut inf_centre = good.clone();
    inf_centre[1].center.y = f64::INFINITY;
    let mut neg_radius = good.clone();
    neg_radius[0].radius = -1.0;
    for (bad, nan) in [
        (&nan_radius, true),
        (&inf_centre, true),
        (&neg_radius, false),
    ] {
        let check = |r: Result<()>, buf: &Vec<u8>| {
            if nan {
                assert!(matches!(r, Err(Error::NonFinite { .. })), "{r:?}");
            } else {
                assert!(matches!(r, Err(Error::NonPositive { .. })), "{r:?}");
            }
            assert!(buf.is_empty(), "wrote {} bytes before failing", buf.len());
        };
        let mut buf = Vec::new();
        check(write_csv3(bad, &mut buf), &buf);
        check(write_yade3(bad, &mut buf), &buf);
        check(write_vtu3(bad, &mut buf), &buf);
        check(write_lammps_data3(bad, &container, 1.0, &mut buf), &buf);
    }
    let mut buf = Vec::new();
    assert!(matches!(
        write_lammps_data3(&good, &container, -1.0, &mut buf),
        Err(Error::NonPositive {
            what: "density",
            ..
        })
    ));
    assert!(matches!(
        write_lammps_data3(&good, &container, f64::NAN, &mut buf),
        Err(Error::NonFinite {
            what: "density",
            ..
        })
    ));
    assert!(matches!(
        write_lammps_data3(&[], &container, 1.0, &mut buf),
        Err(Error::Empty { .. })
    ));
    let flat = Container::Box {
        min: Point3::origin(),
        max: Point3::new(1.0, 0.0, 1.0),
        periodic: [false; 2],
    };
    assert!(matches!(
        write_lammps_data3(&good, &flat, 1.0, &mut buf),
        Err(Error::NonPositive { .. })
    ));
    // A box bound that overflows.
    let huge = [Sphere {
        center: Point3::new(f64::MAX, 0.0, 0.0),
        radius: f64::MAX / 4.0,
    }];
    assert!(matches!(
        write_lammps_data3(&huge, &container, 1.0, &mut buf),
        Err(Error::NonFinite { .. })
    ));
    assert!(buf.is_empty());
    // Empty lists are fine where no box is needed, and read back empty.
    let csv = bytes(|b| write_csv3(&[], b));
    assert!(read_csv3(csv.as_slice()).expect("csv").is_empty());
    let yade = bytes(|b| write_yade3(&[], b));
    assert!(read_yade3(yade.as_slice()).expect("yade").is_empty());
    let vtu = bytes(|b| write_vtu3(&[], b));
    assert!(read_vtu3(vtu.as_slice()).expect("vtu").is_empty());
}

#[test]
fn lammps_parse_errors_name_the_line() {
    let header = "title\n\n2 atoms\n1 atom types\n0 1 xlo xhi\n0 1 ylo yhi\n0 1 zlo zhi\n\nAtoms # sphere\n\n";
    // Atom lines start on line 11.
    let cases: [(&str, usize); 12] = [
        ("1 1 1 1 0 0 0\n2 1 1 1 0 0\n", 12),
        ("1 1 1 1 0 0 0\n2 1 nan 1 0 0 0\n", 12),
        ("1 1 1 1 0 0 0\n2 1 0 1 0 0 0\n", 12),
        ("1 1 1 -5 0 0 0\n2 1 1 1 0 0 0\n", 11),
        ("1 1 1 1 0 0 x\n2 1 1 1 0 0 0\n", 11),
        ("1 1 1 1 0 0 0\n1 1 1 1 0 0 0\n", 12),
        ("1 2 1 1 0 0 0\n2 1 1 1 0 0 0\n", 11),
        ("0 1 1 1 0 0 0\n2 1 1 1 0 0 0\n", 11),
        ("1 1 1 1 0 0 0 0 0 0.5\n2 1 1 1 0 0 0\n", 11),
        ("1 1 1 1 0 0 0\n2 1 1 1 0 0 0\n3 1 1 1 0 0 0\n", 13),
        ("1 1 1 1 0 0 0\n", 9),
        ("1 1 1 1 0 0 0\n2 1 1 1 0 0 inf\n", 12),
    ];
    for (atoms, line) in cases {
        let text = format!("{header}{atoms}");
        assert_eq!(
            parse_line(read_lammps_data3(text.as_bytes())),
            line,
            "{atoms:?}"
        );
    }
    let headers: [(&str, usize); 8] = [
        ("", 1),
        ("t\n2 atoms\n1 0 xlo xhi\n", 3),
        ("t\n2 atoms\n0 1 xlo xhi\n0 1 0 xy xz yz\n", 4),
        ("t\nfoo\n", 2),
        ("t\n2 atoms\nAtoms # atomic\n", 3),
        ("t\nAtoms\n", 2),
        ("t\n\n2 atoms\n", 4),
        ("t\n-2 atoms\n", 2),
    ];
    for (text, line) in headers {
        assert_eq!(
            parse_line(read_lammps_data3(text.as_bytes())),
            line,
            "{text:?}"
        );
    }
    assert_eq!(parse_line(read_lammps_data3(&b"t\n1 atoms\n\xff\n"[..])), 3);
    let second = "t\n1 atoms\nAtoms\n1 1 1 1 0 0 0\nAtoms\n";
    assert_eq!(parse_line(read_lammps_data3(second.as_bytes())), 5);
}

#[test]
fn yade_csv_vtu_parse_errors_name_the_line() {
    let yade: [(&str, usize); 5] = [
        ("# x y z r\n1 2 3 1\n1 2 3\n", 3),
        ("# x y z r\n\n1 2 3 0\n", 3),
        ("#format x_y_z_r_matId\n", 1),
        ("1 2 3 1 5\n", 1),
        ("1 2 NaN 1\n", 1),
    ];
    for (text, line) in yade {
        assert_eq!(parse_line(read_yade3(text.as_bytes())), line, "{text:?}");
    }
    assert_eq!(
        read_yade3("#format x_y_z_r\n# c\n1 2 3 4\n\n".as_bytes())
            .expect("yade")
            .len(),
        1
    );

    let csv: [(&str, usize); 6] = [
        ("", 1),
        ("\nid,x,y,radius\n", 2),
        ("id,x,y,z,radius\n1,0,0,0,1\n2,0,0,0\n", 3),
        ("id,x,y,z,radius\n1,0,0,0,1\n1,0,0,0,1\n", 3),
        ("id,x,y,z,radius\n-1,0,0,0,1\n", 2),
        ("id,x,y,z,radius\n1,0,0,0,-1\n", 2),
    ];
    for (text, line) in csv {
        assert_eq!(parse_line(read_csv3(text.as_bytes())), line, "{text:?}");
    }
    let shuffled = "id, x, y, z, radius\r\n2,0,0,0,2\r\n1,1,1,1,1\r\n";
    let s = read_csv3(shuffled.as_bytes()).expect("csv");
    assert_eq!(s[0].radius, 1.0);
    assert_eq!(s[1].radius, 2.0);

    // VTU: break the file we write at known lines.
    let spheres = random_spheres(3, 2);
    let good = String::from_utf8(bytes(|b| write_vtu3(&spheres, b))).expect("utf8");
    let lines: Vec<&str> = good.lines().collect();
    let edit = |no: usize, with: &str| {
        let mut l = lines.clone();
        l[no - 1] = with;
        l.join("\n") + "\n"
    };
    // Line 6 opens the radius array, line 7 is the first radius, line 18
    // opens the points, line 19 is the first point.
    let cases: [(String, usize); 7] = [
        (edit(7, "-1"), 7),
        (edit(7, "abc"), 7),
        (edit(19, "1 2"), 18),
        (edit(1, "<VTKFile type=\"PolyData\">"), 1),
        (
            edit(
                6,
                r#"<DataArray type="Float64" Name="radius" format="binary">"#,
            ),
            6,
        ),
        (edit(20, "<Foo>"), 20),
        (good.replace("</VTKFile>\n", ""), 2),
    ];
    for (text, line) in cases {
        assert_eq!(parse_line(read_vtu3(text.as_bytes())), line, "{text}");
    }
    let huge = good.replace(
        "NumberOfPoints=\"3\"",
        "NumberOfPoints=\"18446744073709551615\"",
    );
    assert_eq!(parse_line(read_vtu3(huge.as_bytes())), 18);
    let no_radius = good.replace("Name=\"radius\"", "Name=\"r\"");
    assert!(matches!(
        read_vtu3(no_radius.as_bytes()),
        Err(Error::Parse { .. })
    ));
}

/// A finite `f64` of any magnitude, subnormals and signed zeros included.
fn any_finite() -> impl Strategy<Value = f64> {
    use proptest::num::f64::{NEGATIVE, NORMAL, POSITIVE, SUBNORMAL, ZERO};
    (POSITIVE | NEGATIVE | NORMAL | SUBNORMAL | ZERO).prop_filter("finite", |v| v.is_finite())
}

/// Positive radii whose diameters stay finite.
fn any_radius() -> impl Strategy<Value = f64> {
    use proptest::num::f64::{NORMAL, POSITIVE, SUBNORMAL};
    (POSITIVE | NORMAL | SUBNORMAL)
        .prop_filter("finite diameter", |r| *r > 0.0 && (2.0 * r).is_finite())
}

fn any_spheres() -> impl Strategy<Value = Vec<Sphere>> {
    prop::collection::vec(
        (any_finite(), any_finite(), any_finite(), any_radius()).prop_map(|(x, y, z, radius)| {
            Sphere {
                center: Point3::new(x, y, z),
                radius,
            }
        }),
        0..20,
    )
}

/// Lines made of tokens the readers react to, to get past the first check.
fn soup() -> impl Strategy<Value = String> {
    let token = prop::sample::select(vec![
        "1",
        "2",
        "0",
        "-1",
        "1e3",
        "nan",
        "inf",
        "0.5",
        "atoms",
        "atom",
        "types",
        "xlo",
        "xhi",
        "ylo",
        "yhi",
        "zlo",
        "zhi",
        "xy",
        "xz",
        "yz",
        "Atoms",
        "Masses",
        "#",
        "# sphere",
        "sphere",
        "#format",
        "x_y_z_r",
        "id,x,y,z,radius",
        ",",
        "<DataArray",
        "</DataArray>",
        "<Piece",
        "NumberOfPoints=\"1\"",
        ">",
        "<VTKFile",
        "type=\"UnstructuredGrid\"",
        "<UnstructuredGrid>",
        "<Points>",
        "</Points>",
        "<PointData>",
        "Name=\"radius\"",
        "format=\"ascii\"",
        "NumberOfComponents=\"3\"",
        "type=\"Float64\"",
        "/>",
        "<!--",
        "-->",
        "<?xml?>",
        "\u{e9}",
    ]);
    prop::collection::vec(
        prop::collection::vec(token, 0..8).prop_map(|t| t.join(" ")),
        0..30,
    )
    .prop_map(|l| l.join("\n"))
}

proptest! {
    #[test]
    fn readers_never_panic_on_bytes(data in prop::collection::vec(any::<u8>(), 0..512)) {
        let _ = read_lammps_data3(data.as_slice());
        let _ = read_yade3(data.as_slice());
        let _ = read_csv3(data.as_slice());
        let _ = read_vtu3(data.as_slice());
    }

    #[test]
    fn readers_never_panic_on_token_soup(text in soup()) {
        let _ = read_lammps_data3(text.as_bytes());
        let _ = read_yade3(text.as_bytes());
        let _ = read_csv3(text.as_bytes());
        let _ = read_vtu3(text.as_bytes());
    }

    #[test]
    fn readers_never_panic_on_mangled_files(
        spheres in any_spheres(),
        cut in any::<prop::sample::Index>(),
        junk in prop::collection::vec(any::<u8>(), 0..8),
    ) {
        let c = Container::walled_box(Vector3::new(1.0, 1.0, 1.0));
        let mut files = vec![
            bytes(|b| write_csv3(&spheres, b)),
            bytes(|b| write_yade3(&spheres, b)),
            bytes(|b| write_vtu3(&spheres, b)),
        ];
        if let Ok(()) = write_lammps_data3(&spheres, &c, 1.0, &mut Vec::new()) {
            files.push(bytes(|b| write_lammps_data3(&spheres, &c, 1.0, b)));
        }
        for f in files {
            let at = cut.index(f.len() + 1);
            let mut g = f[..at].to_vec();
            g.extend_from_slice(&junk);
            g.extend_from_slice(&f[at..]);
            let _ = read_lammps_data3(g.as_slice());
            let _ = read_yade3(g.as_slice());
            let _ = read_csv3(g.as_slice());
            let _ = read_vtu3(g.as_slice());
        }
    }

    #[test]
    fn random_spheres_round_trip(spheres in any_spheres()) {
        let csv = bytes(|b| write_csv3(&spheres, b));
        assert_identical(&read_csv3(csv.as_slice()).expect("csv"), &spheres);
        let yade = bytes(|b| write_yade3(&spheres, b));
        assert_identical(&read_yade3(yade.as_slice()).expect("yade"), &spheres);
        let vtu = bytes(|b| write_vtu3(&spheres, b));
        assert_identical(&read_vtu3(vtu.as_slice()).expect("vtu"), &spheres);
    }

    #[test]
    fn random_lammps_files_round_trip(
        raw in prop::collection::vec(
            (-1e6..1e6_f64, -1e6..1e6_f64, -1e6..1e6_f64, 1e-6..1e3_f64),
            1..30,
        ),
        density in 1e-3..1e5_f64,
        periodic in any::<[bool; 2]>(),
    ) {
        let spheres: Vec<Sphere> = raw
            .iter()
            .map(|&(x, y, z, radius)| Sphere { center: Point3::new(x, y, z), radius })
            .collect();
        let c = Container::Box {
            min: Point3::new(-10.0, -20.0, -30.0),
            max: Point3::new(10.0, 20.0, 30.0),
            periodic,
        };
        let data = read_lammps_data3(
            bytes(|b| write_lammps_data3(&spheres, &c, density, b)).as_slice(),
        )
        .expect("lammps");
        assert_identical(&data.spheres, &spheres);
        prop_assert!(data.densities.iter().all(|d| d.to_bits() == density.to_bits()));
        for (k, b) in data.bounds.iter().enumerate() {
            if k < 2 && periodic[k] {
                prop_assert_eq!(*b, [[-10.0, 10.0], [-20.0, 20.0]][k]);
            } else {
                for s in &spheres {
                    prop_assert!(b[0] < s.center[k] && s.center[k] < b[1]);
                }
            }
        }
    }
}
