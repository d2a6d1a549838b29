//! The 3D sphere packer (issue "3D dense sphere packing"): solid fractions
//! of the advancing front of open sites in a walled box of side 40 d_max
//! (d ~ U[1, 2], uniform in diameter; default and dense presets), a
//! monodisperse box, a periodic box, the triaxial cylinder H = 2D with its
//! radial profile, closed-mesh containers read from STL, and the export
//! round trips. Every packing goes through the independent checker
//! ([`check_spheres`]: its own cell grid, parry for meshes).
//!
//! Speed is not measured here (this crate has no clock): the criterion
//! bench `packer-spheres/benches/pack3d.rs` (10⁵ spheres) and the
//! `cargo xtask pack --dim 3` timing report (10⁶) do.

use levelset::nalgebra::{Point3, Vector3};
use packer_quadtree::Grading;
use packer_spheres::{
    Boundary, Container, DensePacking3, DensifyParams, Pack3Params, Packing3, Sphere, Target,
    check_spheres, core_solid_fraction, grading_report, max_overlap, pack3d_dense, pack3d_seeded,
    radial_profile, read_csv3, read_lammps_data3, read_vtu3, read_yade3, solid_fraction,
    write_csv3, write_lammps_data3, write_vtu3, write_yade3,
};

use crate::{Case, Check, Error, ExpectedFailure, Tolerance};

pub(crate) fn cases() -> Vec<Case> {
    vec![
        Case {
            name: "pack3d/uniform-box-default",
            description: "d ~ U[1,2] in a walled box of side 40 d_max, default preset: core solid fraction ≥ 0.58, zero overlaps",
            fast: false,
            heavy: false,
            run: || uniform_box(&Pack3Params::default(), 0.58),
        },
        Case {
            name: "pack3d/uniform-box-dense",
            description: "d ~ U[1,2] in a walled box of side 40 d_max, dense preset: core solid fraction ≥ 0.60, zero overlaps",
            fast: false,
            heavy: false,
            run: || uniform_box(&Pack3Params::dense(), 0.60),
        },
        Case {
            name: "pack3d/monodisperse-box",
            description: "monodisperse spheres in a walled box of side 40 d: core solid fraction ≥ 0.58, zero overlaps",
            fast: false,
            heavy: false,
            run: monodisperse_box,
        },
        Case {
            name: "pack3d/periodic-box",
            description: "d ~ U[1,2], box of side 40 d_max periodic in x and y: core solid fraction ≥ 0.58, zero overlaps through the images",
            fast: false,
            heavy: false,
            run: periodic_box,
        },
        Case {
            name: "pack3d/cylinder-h2d",
            description: "d ~ U[1,2] in the triaxial cylinder D = 20 d_max, H = 2D: overall fraction, radial profile (wall annulus and interior), zero overlaps",
            fast: false,
            heavy: false,
            run: cylinder,
        },
        Case {
            name: "pack3d/mesh-stl",
            description: "closed STL containers (a 32-sided prism and an octahedron, written and read by levelset's STL I/O): zero overlaps, solid fraction",
            fast: true,
            heavy: false,
            run: meshes,
        },
        Case {
            name: "pack3d/jammed-periodic",
            description: "≈ 10,000 spheres d ~ U[1,2] in a fully periodic cube, front then densify (affine compression + FIRE): solid fraction ≥ 0.640, zero overlaps through every face, grading kept",
            fast: false,
            heavy: false,
            run: jammed_periodic,
        },
        Case {
            name: "pack3d/jammed-walled",
            description: "front then densify in a walled box (24 d_max) and a triaxial cylinder (D = 12 d_max): core solid fraction ≥ 0.635, zero overlaps",
            fast: false,
            heavy: false,
            run: jammed_walled,
        },
        Case {
            name: "pack3d/exports-roundtrip",
            description: "LAMMPS/LIGGGHTS data, Yade text, CSV and VTU of a packing read back bit for bit",
            fast: true,
            heavy: false,
            run: exports,
        },
    ]
}

/// Side of the periodic cube holding 10,000 spheres of U[1, 2] (mean volume π/6 · 3.75) at 0.64.
fn periodic_side(n: f64, phi: f64) -> f64 {
    (n * std::f64::consts::PI / 6.0 * 3.75 / phi).cbrt()
}

fn dense(boundary: &Boundary, target: f64) -> Result<DensePacking3, Error> {
    let p = DensifyParams {
        target: Target::Fraction(target),
        ..DensifyParams::default()
    };
    pack3d_dense(boundary, &uniform(), &Pack3Params::default(), &p, 1).map_err(Error::computation)
}

fn jammed_periodic() -> Result<Vec<Check>, Error> {
    let l = periodic_side(10_000.0, 0.64);
    let b = Boundary::Periodic {
        min: Point3::origin(),
        max: Point3::new(l, l, l),
    };
    let p = dense(&b, 0.64)?;
    let worst = max_overlap(&p.spheres, &p.boundary).map_err(Error::computation)?;
    let gr = grading_report(&uniform(), &p.spheres).map_err(Error::computation)?;
    Ok(vec![
        Check::new(
            "solid fraction (periodic)",
            0.640,
            p.fraction,
            Tolerance::AtLeast(0.0),
        ),
        Check::new(
            "spheres (about 10,000)",
            10_000.0,
            p.spheres.len() as f64,
            Tolerance::Relative(0.02),
        ),
        Check::new(
            "worst overlap / d (minimum image)",
            0.0,
            worst,
            Tolerance::AtMost(1e-9),
        ),
        Check::new(
            "Cu by mass (packed vs requested)",
            gr.requested.cu,
            gr.packed.cu,
            Tolerance::Relative(0.01),
        ),
    ])
}

fn jammed_walled() -> Result<Vec<Check>, Error> {
    let mut out = Vec::new();
    for (name, c, target) in [
        (
            "box",
            Container::walled_box(Vector3::new(48.0, 48.0, 48.0)),
            0.625,
        ),
        ("cylinder", Container::triaxial(24.0), 0.615),
    ] {
        let p = dense(&Boundary::Walls(c), target)?;
        let Boundary::Walls(c) = &p.boundary else {
            return Err(Error::computation("the densified domain is not walled"));
        };
        let mut checks = vec![
            Check::new(
                "overall solid fraction (target)",
                target,
                p.fraction,
                Tolerance::AtLeast(0.0),
            ),
            core_check(c, &p.spheres, 2.0, 0.635)?,
        ];
        checks.extend(overlap_checks(c, &p.spheres)?);
        for mut ch in checks {
            ch.metric = format!("{name}: {}", ch.metric);
            out.push(ch);
        }
    }
    Ok(out)
}

/// Known failures with their reasons.
pub(crate) const EXPECTED_FAILURES: &[ExpectedFailure] = &[];

fn uniform() -> Grading {
    Grading::Uniform { min: 1.0, max: 2.0 }
}

fn pack(c: &Container, g: &Grading, p: &Pack3Params) -> Result<Packing3, Error> {
    pack3d_seeded(c, g, p, 1).map_err(Error::computation)
}

/// Zero-overlap checks of the independent checker.
fn overlap_checks(c: &Container, s: &[Sphere]) -> Result<Vec<Check>, Error> {
    let r = check_spheres(c, s, 1e-9).map_err(Error::computation)?;
    let pair = if r.worst_normalised_gap.is_finite() {
        r.worst_normalised_gap
    } else {
        1.0
    };
    Ok(vec![
        Check::new("worst pair gap / d", -1e-9, pair, Tolerance::AtLeast(0.0)),
        Check::new(
            "worst wall gap / d",
            -1e-9,
            r.worst_normalised_wall_gap,
            Tolerance::AtLeast(0.0),
        ),
    ])
}

fn core_check(c: &Container, s: &[Sphere], d_max: f64, bar: f64) -> Result<Check, Error> {
    let core = core_solid_fraction(c, s, 2.0 * d_max).map_err(Error::computation)?;
    Ok(Check::new(
        "core solid fraction (2 d_max from the walls)",
        bar,
        core.fraction,
        Tolerance::AtLeast(0.0),
    ))
}

fn uniform_box(params: &Pack3Params, bar: f64) -> Result<Vec<Check>, Error> {
    let c = Container::walled_box(Vector3::new(80.0, 80.0, 80.0));
    let g = uniform();
    let p = pack(&c, &g, params)?;
    let mut out = vec![core_check(&c, &p.spheres, 2.0, bar)?];
    let overall = solid_fraction(&c, &p.spheres).map_err(Error::computation)?;
    out.push(Check::new(
        "overall solid fraction (walls included)",
        0.58,
        overall,
        Tolerance::AtLeast(0.0),
    ));
    let gr = grading_report(&g, &p.spheres).map_err(Error::computation)?;
    out.push(Check::new(
        "Cu by mass (packed vs requested)",
        gr.requested.cu,
        gr.packed.cu,
        Tolerance::Relative(0.01),
    ));
    out.push(Check::new(
        "max deviation of the mass passing curve",
        0.0,
        gr.max_deviation,
        Tolerance::AtMost(0.01),
    ));
    out.extend(overlap_checks(&c, &p.spheres)?);
    Ok(out)
}

fn monodisperse_box() -> Result<Vec<Check>, Error> {
    let c = Container::walled_box(Vector3::new(40.0, 40.0, 40.0));
    let p = pack(
        &c,
        &Grading::Constant { diameter: 1.0 },
        &Pack3Params::default(),
    )?;
    let mut out = vec![core_check(&c, &p.spheres, 1.0, 0.58)?];
    out.extend(overlap_checks(&c, &p.spheres)?);
    Ok(out)
}

fn periodic_box() -> Result<Vec<Check>, Error> {
    let c = Container::Box {
        min: Point3::origin(),
        max: Point3::new(80.0, 80.0, 80.0),
        periodic: [true, true],
    };
    let p = pack(&c, &uniform(), &Pack3Params::default())?;
    let mut out = vec![core_check(&c, &p.spheres, 2.0, 0.58)?];
    out.extend(overlap_checks(&c, &p.spheres)?);
    Ok(out)
}

fn cylinder() -> Result<Vec<Check>, Error> {
    let c = Container::triaxial(40.0);
    let p = pack(&c, &uniform(), &Pack3Params::default())?;
    let overall = solid_fraction(&c, &p.spheres).map_err(Error::computation)?;
    let mut out = vec![
        Check::new(
            "overall solid fraction",
            0.58,
            overall,
            Tolerance::AtLeast(0.0),
        ),
        core_check(&c, &p.spheres, 2.0, 0.58)?,
    ];
    // Annuli of d_max / 2 over the whole height.
    let prof = radial_profile(&c, &p.spheres, 20).map_err(Error::computation)?;
    let interior: Vec<f64> = prof[..prof.len() - 2]
        .iter()
        .map(|b| b.solid_fraction)
        .collect();
    let mean = interior.iter().sum::<f64>() / interior.len() as f64;
    let spread = interior
        .iter()
        .map(|f| (f - mean).abs())
        .fold(0.0, f64::max);
    out.push(Check::new(
        "interior annuli (axis to 2 d_max from the wall): mean fraction",
        0.58,
        mean,
        Tolerance::AtLeast(0.0),
    ));
    out.push(Check::new(
        "interior annuli: largest deviation from their mean (homogeneity)",
        0.0,
        spread,
        Tolerance::AtMost(0.02),
    ));
    if let Some(w) = prof.last() {
        out.push(Check::new(
            "wall annulus (outer d_max / 2): fraction, the wall effect",
            0.45,
            w.solid_fraction,
            Tolerance::AtLeast(0.0),
        ));
    }
    out.extend(overlap_checks(&c, &p.spheres)?);
    Ok(out)
}

/// A closed surface through STL bytes, as a user's file would come in.
fn via_stl(vertices: Vec<Point3<f64>>, triangles: Vec<[usize; 3]>) -> Result<Container, Error> {
    let mesh = levelset::TriMesh::new(vertices, triangles).map_err(Error::computation)?;
    let mut bytes = Vec::new();
    levelset::io::write_stl_binary(&mut bytes, &mesh).map_err(Error::computation)?;
    let read = levelset::io::read_stl(&bytes[..]).map_err(Error::computation)?;
    let (closed, _) = read
        .prepare_closed(levelset::Orientation::Repair)
        .map_err(Error::computation)?;
    Container::mesh(closed).map_err(Error::computation)
}

fn prism(n: usize, r: f64, h: f64) -> (Vec<Point3<f64>>, Vec<[usize; 3]>) {
    let mut v = Vec::new();
    for z in [0.0, h] {
        for i in 0..n {
            let a = std::f64::consts::TAU * i as f64 / n as f64;
            v.push(Point3::new(r * a.cos(), r * a.sin(), z));
        }
    }
    v.push(Point3::new(0.0, 0.0, 0.0));
    v.push(Point3::new(0.0, 0.0, h));
    let (cb, ct) = (2 * n, 2 * n + 1);
    let mut t = Vec::new();
    for i in 0..n {
        let j = (i + 1) % n;
        t.push([cb, j, i]);
        t.push([ct, n + i, n + j]);
        t.push([i, j, n + j]);
        t.push([i, n + j, n + i]);
    }
    (v, t)
}

fn octahedron(r: f64) -> (Vec<Point3<f64>>, Vec<[usize; 3]>) {
    let v = vec![
        Point3::new(r, 0.0, 0.0),
        Point3::new(-r, 0.0, 0.0),
        Point3::new(0.0, r, 0.0),
        Point3::new(0.0, -r, 0.0),
        Point3::new(0.0, 0.0, r),
        Point3::new(0.0, 0.0, -r),
    ];
    let t = vec![
        [0, 2, 4],
        [2, 1, 4],
        [1, 3, 4],
        [3, 0, 4],
        [2, 0, 5],
        [1, 2, 5],
        [3, 1, 5],
        [0, 3, 5],
    ];
    (v, t)
}

fn meshes() -> Result<Vec<Check>, Error> {
    let mut out = Vec::new();
    for (name, (v, t), bar) in [
        (
            "32-sided prism D = 10 d_max, H = 10 d_max",
            prism(32, 10.0, 20.0),
            0.55,
        ),
        ("octahedron of circumradius 7 d_max", octahedron(14.0), 0.50),
    ] {
        let c = via_stl(v, t)?;
        let p = pack(&c, &uniform(), &Pack3Params::default())?;
        let f = solid_fraction(&c, &p.spheres).map_err(Error::computation)?;
        out.push(Check::new(
            format!("{name}: overall solid fraction"),
            bar,
            f,
            Tolerance::AtLeast(0.0),
        ));
        for mut ch in overlap_checks(&c, &p.spheres)? {
            ch.metric = format!("{name}: {}", ch.metric);
            out.push(ch);
        }
    }
    Ok(out)
}

fn exports() -> Result<Vec<Check>, Error> {
    let c = Container::walled_box(Vector3::new(12.0, 12.0, 12.0));
    let p = pack(&c, &uniform(), &Pack3Params::default())?;
    let s = &p.spheres;
    let e = Error::computation;
    let mismatches = |back: &[Sphere]| -> f64 {
        if back.len() != s.len() {
            return s.len().max(back.len()) as f64;
        }
        s.iter()
            .zip(back)
            .filter(|(a, b)| {
                a.radius.to_bits() != b.radius.to_bits()
                    || (0..3).any(|k| a.center[k].to_bits() != b.center[k].to_bits())
            })
            .count() as f64
    };
    let mut b = Vec::new();
    write_lammps_data3(s, &c, 2650.0, &mut b).map_err(e)?;
    let lammps = read_lammps_data3(&b[..]).map_err(e)?.spheres;
    let mut b = Vec::new();
    write_yade3(s, &mut b).map_err(e)?;
    let yade = read_yade3(&b[..]).map_err(e)?;
    let mut b = Vec::new();
    write_csv3(s, &mut b).map_err(e)?;
    let csv = read_csv3(&b[..]).map_err(e)?;
    let mut b = Vec::new();
    write_vtu3(s, &mut b).map_err(e)?;
    let vtu = read_vtu3(&b[..]).map_err(e)?;
    Ok(vec![
        Check::new(
            "LAMMPS data: spheres differing",
            0.0,
            mismatches(&lammps),
            Tolerance::Within(0.0),
        ),
        Check::new(
            "Yade text: spheres differing",
            0.0,
            mismatches(&yade),
            Tolerance::Within(0.0),
        ),
        Check::new(
            "CSV: spheres differing",
            0.0,
            mismatches(&csv),
            Tolerance::Within(0.0),
        ),
        Check::new(
            "VTU: spheres differing",
            0.0,
            mismatches(&vtu),
            Tolerance::Within(0.0),
        ),
    ])
}
