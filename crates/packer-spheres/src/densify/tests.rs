//! Densification: fractions reached with no overlap (an O(n²) checker of its own), the grading
//! kept, the FCC lattice as an oracle, determinism for any thread count, bad input.

use super::*;
use crate::{Pack3Params, pack3d_seeded};
use packer_quadtree::Grading;

/// Worst overlap over pairs (minimum image on the periodic axes) and walls, as a fraction of
/// the smaller diameter: a plain O(n²) loop independent of the module.
fn brute_overlap(b: &Boundary, s: &[Sphere]) -> f64 {
    let (per, lo, hi) = match b {
        Boundary::Periodic { min, max } => ([true; 3], *min, *max),
        Boundary::Walls(c) => {
            let p = c.periodic();
            let (lo, hi) = c.bbox();
            ([p[0], p[1], false], lo, hi)
        }
    };
    let mut worst = f64::NEG_INFINITY;
    for (i, a) in s.iter().enumerate() {
        if let Boundary::Walls(c) = b {
            worst = worst.max((a.radius - c.clearance(&a.center)) / (2.0 * a.radius));
        }
        for q in &s[i + 1..] {
            let mut d = a.center - q.center;
            for k in 0..3 {
                if per[k] {
                    let l = hi[k] - lo[k];
                    d[k] -= (d[k] / l).round() * l;
                }
            }
            worst = worst.max((a.radius + q.radius - d.norm()) / (2.0 * a.radius.min(q.radius)));
        }
    }
    worst
}

fn volume(s: &[Sphere]) -> f64 {
    s.iter()
        .map(|p| 4.0 / 3.0 * std::f64::consts::PI * p.radius.powi(3))
        .sum()
}

/// The front's packing of U[1, 2] in a cube of side `l`, x/y periodic, z walls.
fn front(l: f64) -> Vec<Sphere> {
    let c = Container::Box {
        min: Point3::origin(),
        max: Point3::new(l, l, l),
        periodic: [true, true],
    };
    pack3d_seeded(
        &c,
        &Grading::Uniform { min: 1.0, max: 2.0 },
        &Pack3Params::default(),
        7,
    )
    .expect("front")
    .spheres
}

fn periodic(l: f64) -> Boundary {
    Boundary::Periodic {
        min: Point3::origin(),
        max: Point3::new(l, l, l),
    }
}

fn target(f: f64) -> DensifyParams {
    DensifyParams {
        target: Target::Fraction(f),
        ..DensifyParams::default()
    }
}

#[test]
fn periodic_box_reaches_the_fraction_without_overlap() {
    let s = front(14.0);
    let b = periodic(14.0);
    let d = densify(&s, &b, &target(0.625)).expect("densify");
    assert!((d.fraction - 0.625).abs() < 1e-12, "{}", d.fraction);
    // the boundary is the compressed cube, and the fraction is measured on it
    approx::assert_relative_eq!(
        d.fraction,
        volume(&d.spheres) / d.boundary.volume(),
        max_relative = 1e-12
    );
    assert!(brute_overlap(&d.boundary, &d.spheres) <= 1e-12);
    assert!(d.stats.max_overlap <= 1e-12);
    // radii untouched, in input order
    for (a, b) in s.iter().zip(&d.spheres) {
        assert_eq!(a.radius, b.radius);
    }
    assert!(d.stats.initial_fraction < 0.62);
}

#[test]
fn walled_box_and_cylinder_reach_the_fraction() {
    let l = 14.0;
    let s = front(l);
    let walled = Boundary::Walls(Container::Box {
        min: Point3::origin(),
        max: Point3::new(l, l, l),
        periodic: [true, true],
    });
    let d = densify(&s, &walled, &target(0.61)).expect("box");
    assert!((d.fraction - 0.61).abs() < 1e-12);
    assert!(brute_overlap(&d.boundary, &d.spheres) <= 1e-12);

    let cyl = Container::triaxial(12.0);
    let s = pack3d_seeded(
        &cyl,
        &Grading::Uniform { min: 1.0, max: 2.0 },
        &Pack3Params::default(),
        3,
    )
    .expect("front")
    .spheres;
    // a cylinder 6 d_max across is mostly wall layers: 0.575 overall
    let d = densify(&s, &Boundary::Walls(cyl), &target(0.575)).expect("cylinder");
    assert!((d.fraction - 0.575).abs() < 1e-12);
    assert!(brute_overlap(&d.boundary, &d.spheres) <= 1e-12);
    match d.boundary {
        Boundary::Walls(Container::Cylinder { radius, height, .. }) => {
            // scaled about its centre: the aspect is kept
            approx::assert_relative_eq!(height / radius, 4.0, max_relative = 1e-12);
            assert!(radius < 6.0);
        }
        ref other => panic!("{other:?}"),
    }
}

/// FCC spheres of radius 0.5 spread affinely to φ = 0.5 compress back to 0.74 (below the
/// lattice's π/√18 = 0.7405) without a single relaxation step: the oracle of the compression
/// and of the final expansion.
#[test]
fn fcc_lattice_compresses_to_0_74() {
    let n = 4;
    let a = std::f64::consts::SQRT_2; // lattice constant of touching spheres of diameter 1
    let grow = (std::f64::consts::PI / 18.0_f64.sqrt() / 0.5).cbrt();
    let mut s = Vec::new();
    for i in 0..n {
        for j in 0..n {
            for k in 0..n {
                for o in [
                    [0.0, 0.0, 0.0],
                    [0.5, 0.5, 0.0],
                    [0.5, 0.0, 0.5],
                    [0.0, 0.5, 0.5],
                ] {
                    let p = Point3::new(
                        (i as f64 + o[0] + 0.25) * a * grow,
                        (j as f64 + o[1] + 0.25) * a * grow,
                        (k as f64 + o[2] + 0.25) * a * grow,
                    );
                    s.push(Sphere {
                        center: p,
                        radius: 0.5,
                    });
                }
            }
        }
    }
    let l = n as f64 * a * grow;
    let b = periodic(l);
    approx::assert_relative_eq!(volume(&s) / b.volume(), 0.5, max_relative = 1e-12);
    let d = densify(&s, &b, &target(0.74)).expect("fcc");
    assert!((d.fraction - 0.74).abs() < 1e-12);
    assert!(brute_overlap(&d.boundary, &d.spheres) <= 1e-12);
    assert_eq!(d.stats.iterations, 0);
}

#[test]
fn beyond_jamming_is_a_structured_error() {
    let s = front(14.0);
    let p = DensifyParams {
        max_iterations: 400,
        min_step: 2e-3,
        ..target(0.72)
    };
    match densify(&s, &periodic(14.0), &p) {
        Err(Error::FractionNotReached { requested, reached }) => {
            assert_eq!(requested, 0.72);
            assert!(reached > 0.6 && reached < 0.72, "{reached}");
            let msg = Error::FractionNotReached { requested, reached }.to_string();
            assert!(msg.contains("0.72") && msg.contains("jams"), "{msg}");
        }
        other => panic!("{other:?}"),
    }
}

#[test]
fn jammed_target_stops_at_the_jamming_point_without_overlap() {
    let s = front(14.0);
    let p = DensifyParams {
        target: Target::Jammed,
        max_iterations: 600,
        min_step: 2e-3,
        ..DensifyParams::default()
    };
    let d = densify(&s, &periodic(14.0), &p).expect("jammed");
    assert!(d.fraction > 0.62 && d.fraction < 0.70, "{}", d.fraction);
    assert!(d.stats.steps_rejected > 0);
    assert!(brute_overlap(&d.boundary, &d.spheres) <= 1e-12);
}

#[test]
fn identical_for_any_thread_count() {
    let s = front(14.0);
    let run = |threads| {
        rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .build()
            .expect("pool")
            .install(|| densify(&s, &periodic(14.0), &target(0.62)).expect("densify"))
    };
    let (a, b) = (run(1), run(2));
    assert_eq!(a.fraction.to_bits(), b.fraction.to_bits());
    for (p, q) in a.spheres.iter().zip(&b.spheres) {
        assert_eq!(p, q);
    }
    assert_eq!(a.stats, b.stats);
}

#[test]
fn max_overlap_sees_the_periodic_images() {
    let b = periodic(10.0);
    let s = [
        Sphere {
            center: Point3::new(0.1, 5.0, 5.0),
            radius: 0.5,
        },
        Sphere {
            center: Point3::new(9.9, 5.0, 5.0),
            radius: 0.5,
        },
    ];
    // 0.2 apart through the face: overlap 0.8 of a diameter
    approx::assert_relative_eq!(max_overlap(&s, &b).expect("ok"), 0.8, max_relative = 1e-12);
    let walled = Boundary::Walls(Container::walled_box(nalgebra::Vector3::new(
        10.0, 10.0, 10.0,
    )));
    // no image in a walled box, but both spheres cross a wall by 0.4
    approx::assert_relative_eq!(
        max_overlap(&s, &walled).expect("ok"),
        0.4,
        max_relative = 1e-12
    );
    assert_eq!(max_overlap(&[], &b).expect("empty"), 0.0);
}

#[test]
fn bad_input_is_refused() {
    let s = front(14.0);
    let b = periodic(14.0);
    for (f, bad) in [
        (f64::NAN, "NaN"),
        (0.75, "above"),
        (0.0, "zero"),
        (-0.1, "negative"),
    ] {
        let e = densify(&s, &b, &target(f)).expect_err(bad);
        assert!(
            matches!(e, Error::NonFinite { .. } | Error::Parameter { .. }),
            "{bad}: {e}"
        );
    }
    // below the packing's own fraction
    assert!(matches!(
        densify(&s, &b, &target(0.3)),
        Err(Error::Parameter { .. })
    ));
    assert!(matches!(
        densify(&[], &b, &target(0.6)),
        Err(Error::Empty { .. })
    ));
    let mut nan = s.clone();
    nan[3].center.y = f64::NAN;
    assert!(matches!(
        densify(&nan, &b, &target(0.6)),
        Err(Error::NonFinite { .. })
    ));
    let mut zero = s.clone();
    zero[0].radius = 0.0;
    assert!(matches!(
        densify(&zero, &b, &target(0.6)),
        Err(Error::NonPositive { .. })
    ));
    // a periodic side under 4 d_max
    assert!(matches!(
        densify(&s, &periodic(7.0), &target(0.6)),
        Err(Error::DomainTooSmall { .. })
    ));
    let mesh = levelset::TriMesh::new(
        vec![
            Point3::new(0.0, 0.0, 0.0),
            Point3::new(20.0, 0.0, 0.0),
            Point3::new(0.0, 20.0, 0.0),
            Point3::new(0.0, 0.0, 20.0),
        ],
        vec![[0, 2, 1], [0, 1, 3], [0, 3, 2], [1, 2, 3]],
    )
    .expect("tetra");
    let c = Container::mesh(mesh).expect("mesh");
    assert!(matches!(
        densify(&s, &Boundary::Walls(c), &target(0.6)),
        Err(Error::WrongContainer { .. })
    ));
    for p in [
        DensifyParams {
            max_iterations: 0,
            ..DensifyParams::default()
        },
        DensifyParams {
            tolerance: 0.1,
            ..DensifyParams::default()
        },
        DensifyParams {
            first_step: 1e-6,
            ..DensifyParams::default()
        },
        DensifyParams {
            min_step: f64::NAN,
            ..DensifyParams::default()
        },
    ] {
        assert!(densify(&s, &b, &p).is_err(), "{p:?}");
    }
    // an input with overlaps it cannot relax is an error, not a silent result
    let mut heap = s.clone();
    for p in heap.iter_mut().take(20) {
        p.center = Point3::new(7.0, 7.0, 7.0);
    }
    let p = DensifyParams {
        max_iterations: 3,
        ..target(0.62)
    };
    assert!(matches!(
        densify(&heap, &b, &p),
        Err(Error::NotConverged { .. })
    ));
}

#[test]
fn pack3d_dense_fills_the_requested_domain_at_the_target() {
    let g = Grading::Uniform { min: 1.0, max: 2.0 };
    for (b, f) in [
        (periodic(14.0), 0.63),
        (
            Boundary::Walls(Container::walled_box(nalgebra::Vector3::new(
                16.0, 16.0, 16.0,
            ))),
            // 8 d_max wide: the wall layers hold the overall fraction below 0.59
            0.58,
        ),
    ] {
        let p = pack3d_dense(&b, &g, &Pack3Params::default(), &target(f), 5).expect("dense");
        assert!(
            p.fraction >= f - 1e-12 && p.fraction < f + 0.002,
            "{}",
            p.fraction
        );
        approx::assert_relative_eq!(p.boundary.volume(), b.volume(), max_relative = 1e-12);
        assert!(brute_overlap(&p.boundary, &p.spheres) <= 1e-12);
        assert_eq!(p.placed - p.removed, p.spheres.len());
        // every size within the grading
        assert!(p.spheres.iter().all(|s| (0.5..=1.0).contains(&s.radius)));
    }
}
