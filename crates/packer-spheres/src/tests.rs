//! 3D packer: zero overlaps in every container (an O(n²) checker of its
//! own), closed forms against `contact3d`, golden digest for 1 and 2
//! threads, bad input.

use super::*;
use levelset::TriMesh;
use nalgebra::Vector3;
use packer_contact::contact3d;
use proptest::prelude::*;

/// Worst normalised gap over pairs (periodic images in x/y) and walls:
/// `min(gap / d_small)`; a plain O(n²) loop independent of the packer.
fn brute_worst(container: &Container, s: &[Sphere]) -> f64 {
    let per = container.periodic();
    let (lo, hi) = container.bbox();
    let mut worst = f64::INFINITY;
    for (i, a) in s.iter().enumerate() {
        let wall = container.clearance(&a.center) - a.radius;
        worst = worst.min(wall / (2.0 * a.radius));
        for b in &s[i + 1..] {
            let mut d = a.center - b.center;
            for k in 0..2 {
                if per[k] {
                    let l = hi[k] - lo[k];
                    d[k] -= (d[k] / l).round() * l;
                }
            }
            let gap = d.norm() - a.radius - b.radius;
            worst = worst.min(gap / (2.0 * a.radius.min(b.radius)));
        }
    }
    worst
}

fn digest(p: &Packing3) -> u64 {
    let mut h: u64 = 0xcbf2_9ce4_8422_2325;
    for s in &p.spheres {
        for v in [s.center.x, s.center.y, s.center.z, s.radius] {
            for b in v.to_bits().to_le_bytes() {
                h ^= u64::from(b);
                h = h.wrapping_mul(0x0000_0100_0000_01b3);
            }
        }
    }
    h
}

fn cube_mesh(side: f64) -> TriMesh {
    let v: Vec<Point3<f64>> = (0..8)
        .map(|i| {
            Point3::new(
                side * f64::from(i & 1),
                side * f64::from((i >> 1) & 1),
                side * f64::from((i >> 2) & 1),
            )
        })
        .collect();
    let t = vec![
        [0, 2, 1],
        [1, 2, 3],
        [4, 5, 6],
        [5, 7, 6],
        [0, 1, 4],
        [1, 5, 4],
        [2, 6, 3],
        [3, 6, 7],
        [0, 4, 2],
        [2, 4, 6],
        [1, 3, 5],
        [3, 7, 5],
    ];
    TriMesh::new(v, t).expect("cube")
}

/// A vertical prism over a regular `n`-gon (a faceted cylinder), radius
/// `r`, height `h`.
fn prism_mesh(n: usize, r: f64, h: f64) -> TriMesh {
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
    TriMesh::new(v, t).expect("prism")
}

fn uniform() -> Grading {
    Grading::Uniform { min: 1.0, max: 2.0 }
}

#[test]
fn walled_box_is_dense_and_overlap_free() {
    let c = Container::walled_box(Vector3::new(14.0, 14.0, 14.0));
    let p = pack3d_seeded(&c, &uniform(), &Pack3Params::default(), 3).expect("pack");
    assert!(p.spheres.len() > 300, "{}", p.spheres.len());
    let w = brute_worst(&c, &p.spheres);
    assert!(w >= -1e-9, "worst {w}");
    let solid: f64 = p
        .spheres
        .iter()
        .map(|s| 4.0 / 3.0 * std::f64::consts::PI * s.radius.powi(3))
        .sum::<f64>()
        / c.volume();
    assert!(solid > 0.5, "solid fraction {solid}");
}

#[test]
fn every_container_is_overlap_free() {
    let containers = [
        Container::Box {
            min: Point3::new(-3.0, 1.0, 2.0),
            max: Point3::new(9.0, 11.0, 12.0),
            periodic: [true, true],
        },
        Container::Box {
            min: Point3::origin(),
            max: Point3::new(10.0, 12.0, 9.0),
            periodic: [true, false],
        },
        Container::triaxial(10.0),
        Container::mesh(cube_mesh(10.0)).expect("cube container"),
        Container::mesh(prism_mesh(12, 6.0, 9.0)).expect("prism container"),
    ];
    for (i, c) in containers.iter().enumerate() {
        for params in [Pack3Params::default(), Pack3Params::dense()] {
            let p = pack3d_seeded(c, &uniform(), &params, 5).expect("pack");
            let w = brute_worst(c, &p.spheres);
            let solid: f64 = p
                .spheres
                .iter()
                .map(|s| 4.0 / 3.0 * std::f64::consts::PI * s.radius.powi(3))
                .sum::<f64>()
                / c.volume();
            println!(
                "container {i}: n {} solid {solid:.3} worst {w:e}",
                p.spheres.len()
            );
            assert!(w >= -1e-9, "container {i}: worst {w}");
            assert!(solid > 0.4, "container {i}: solid {solid}");
        }
    }
}

#[test]
fn periodic_box_wraps_centres_and_uses_images() {
    let c = Container::Box {
        min: Point3::origin(),
        max: Point3::new(10.0, 10.0, 8.0),
        periodic: [true, true],
    };
    let p = pack3d_seeded(
        &c,
        &Grading::Constant { diameter: 1.0 },
        &Pack3Params::default(),
        1,
    )
    .expect("pack");
    for s in &p.spheres {
        assert!((0.0..10.0).contains(&s.center.x) && (0.0..10.0).contains(&s.center.y));
    }
    // Spheres cross the periodic faces (no wall there).
    assert!(p.spheres.iter().any(|s| s.center.x < s.radius * 0.9));
    assert!(brute_worst(&c, &p.spheres) >= -1e-9);
}

#[test]
fn closed_forms_agree_with_contact3d() {
    use rand::{Rng, SeedableRng};
    let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(9);
    let mut checked = 0;
    for _ in 0..2000 {
        let r = rng.random_range(0.3..1.0);
        let c: Vec<(Point3<f64>, f64)> = (0..3)
            .map(|_| {
                (
                    Point3::new(
                        rng.random_range(-2.0..2.0),
                        rng.random_range(-2.0..2.0),
                        rng.random_range(-2.0..2.0),
                    ),
                    rng.random_range(0.3..1.0),
                )
            })
            .collect();
        let want = contact3d::sphere_three_spheres(&[c[0], c[1], c[2]], r);
        let got = front::tests_api::three(&c, r);
        let want: Vec<Point3<f64>> = want.iter().collect();
        if want.len() == 2 {
            assert_eq!(got.len(), 2);
            for w in &want {
                let best = got
                    .iter()
                    .map(|g| (g - w).norm())
                    .fold(f64::INFINITY, f64::min);
                assert!(best < 1e-9, "{best}");
            }
            checked += 1;
        }
    }
    assert!(checked > 100);
}

#[test]
fn sphere_touches_cylinder_wall_exactly() {
    // Circle of a front and an obstacle meets the offset cylinder: every
    // root is at the right distance from the axis and from both centres.
    for (cf, ca) in [
        ([3.0, 0.0, 1.0], [3.2, 1.5, 1.1]),
        ([-2.5, 2.0, 0.5], [-1.0, 2.8, 1.5]),
    ] {
        let (rf, ra, r, radius) = (0.6, 0.7, 0.5, 4.0);
        let pts = front::tests_api::circle_cylinder(cf, rf, ca, ra, r, radius);
        assert!(!pts.is_empty());
        for p in pts {
            let dist = |c: [f64; 3]| {
                ((p[0] - c[0]).powi(2) + (p[1] - c[1]).powi(2) + (p[2] - c[2]).powi(2)).sqrt()
            };
            assert!((dist(cf) - rf - r).abs() < 1e-9);
            assert!((dist(ca) - ra - r).abs() < 1e-9);
            assert!((p[0].hypot(p[1]) - (radius - r)).abs() < 1e-9);
        }
    }
}

/// Golden determinism: guards the packer's arithmetic, site order and
/// the portfolio's choice; identical with 1 and 2 threads. A deliberate
/// change of the algorithm re-mints it (copy the printed values).
#[test]
fn golden_digest_for_one_and_two_threads() {
    let c = Container::walled_box(Vector3::new(12.0, 12.0, 12.0));
    let run = |threads: usize, params: Pack3Params| {
        let pool = rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .build()
            .expect("pool");
        pool.install(|| {
            let p = pack3d_seeded(&c, &uniform(), &params, 1).expect("pack");
            (p.spheres.len(), digest(&p))
        })
    };
    let d1 = run(1, Pack3Params::default());
    let d2 = run(2, Pack3Params::default());
    let e1 = run(1, Pack3Params::dense());
    let e2 = run(2, Pack3Params::dense());
    println!("golden {:?}", (d1, e1));
    assert_eq!(d1, d2);
    assert_eq!(e1, e2);
    assert_eq!((d1, e1), GOLDEN);
}

const GOLDEN: ((usize, u64), (usize, u64)) =
    ((470, 0x6d0a_d425_2c25_a6d0), (534, 0xb23d_b129_8dec_42e2));

#[test]
fn bad_input_is_a_structured_error() {
    let tiny = Container::walled_box(Vector3::new(1.5, 5.0, 5.0));
    assert!(matches!(
        pack3d_seeded(&tiny, &uniform(), &Pack3Params::default(), 1),
        Err(Error::DomainTooSmall { .. })
    ));
    let cyl = Container::Cylinder {
        base: Point3::origin(),
        radius: 0.9,
        height: 10.0,
    };
    assert!(matches!(
        pack3d_seeded(&cyl, &uniform(), &Pack3Params::default(), 1),
        Err(Error::DomainTooSmall { .. })
    ));
    // An open mesh: one face missing.
    let cube = cube_mesh(10.0);
    let mut t = cube.triangles().to_vec();
    t.pop();
    let open = TriMesh::new(cube.vertices().to_vec(), t).expect("mesh");
    assert!(matches!(Container::mesh(open), Err(Error::Mesh(_))));
    // Gradings with negative or non-monotone rows.
    let c = Container::walled_box(Vector3::new(10.0, 10.0, 10.0));
    for g in [
        Grading::Sieve {
            sizes: vec![-1.0, 2.0],
            passing: vec![0.0, 100.0],
        },
        Grading::Sieve {
            sizes: vec![1.0, 2.0, 3.0],
            passing: vec![0.0, 60.0, 40.0],
        },
        Grading::Uniform { min: 2.0, max: 1.0 },
        Grading::Constant { diameter: f64::NAN },
    ] {
        assert!(
            pack3d_seeded(&c, &g, &Pack3Params::default(), 1).is_err(),
            "{g:?}"
        );
    }
    // A count beyond memory (a unit mistake: metres of container, mm sizes).
    let huge = Container::walled_box(Vector3::new(1e4, 1e4, 1e4));
    assert!(matches!(
        pack3d_seeded(
            &huge,
            &Grading::Constant { diameter: 1.0 },
            &Pack3Params::default(),
            1
        ),
        Err(Error::TooManyParticles { .. })
    ));
    // Bad container geometry and parameters.
    let flat = Container::Box {
        min: Point3::origin(),
        max: Point3::new(10.0, 10.0, f64::NAN),
        periodic: [false; 2],
    };
    assert!(pack3d_seeded(&flat, &uniform(), &Pack3Params::default(), 1).is_err());
    let p0 = Pack3Params {
        lookahead: 0,
        ..Pack3Params::default()
    };
    assert!(matches!(
        pack3d_seeded(&c, &uniform(), &p0, 1),
        Err(Error::Parameter { .. })
    ));
    // A periodic side too short for the images.
    let thin = Container::Box {
        min: Point3::origin(),
        max: Point3::new(5.0, 20.0, 20.0),
        periodic: [true, false],
    };
    assert!(matches!(
        pack3d_seeded(&thin, &uniform(), &Pack3Params::default(), 1),
        Err(Error::DomainTooSmall { .. })
    ));
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(24))]
    /// Zero overlaps for random containers and gradings.
    #[test]
    fn random_containers_and_gradings_are_overlap_free(
        kind in 0usize..4,
        sx in 6.0f64..11.0,
        sy in 6.0f64..11.0,
        sz in 5.0f64..9.0,
        dmin in 0.6f64..1.2,
        ratio in 1.0f64..2.5,
        sieve in any::<bool>(),
        seed in 0u64..1000,
    ) {
        let dmax = dmin * ratio;
        let c = match kind {
            0 => Container::walled_box(Vector3::new(sx, sy, sz)),
            1 => Container::Box {
                min: Point3::origin(),
                max: Point3::new(sx.max(4.0 * dmax), sy.max(4.0 * dmax), sz),
                periodic: [true, true],
            },
            2 => Container::Cylinder { base: Point3::new(1.0, -2.0, 0.5), radius: 0.5 * sx, height: sz },
            _ => Container::mesh(prism_mesh(9, 0.5 * sx, sz)).expect("prism"),
        };
        let g = if sieve && ratio > 1.01 {
            Grading::Sieve { sizes: vec![dmin, 0.5 * (dmin + dmax), dmax], passing: vec![0.0, 40.0, 100.0] }
        } else {
            Grading::Uniform { min: dmin, max: dmax }
        };
        match pack3d_seeded(&c, &g, &Pack3Params::default(), seed) {
            Ok(p) => {
                let w = brute_worst(&c, &p.spheres);
                prop_assert!(w >= -1e-9, "worst {}", w);
            }
            Err(Error::DomainTooSmall { .. }) => {}
            Err(e) => prop_assert!(false, "{}", e),
        }
    }
}

/// Slab-parallel packing ([`slabs`]): every box kind is overlap-free, the
/// slabs are really used, the result does not depend on the thread count,
/// and the solid fraction stays within 0.01 of the sequential front's.
#[test]
fn slab_packing_is_overlap_free_deterministic_and_dense() {
    let params = Pack3Params {
        slabs: 4,
        slab_cylinders: true,
        ..Pack3Params::default()
    };
    let boxes = [
        Container::walled_box(Vector3::new(50.0, 10.0, 10.0)),
        Container::Box {
            min: Point3::new(-3.0, 0.0, 0.0),
            max: Point3::new(47.0, 10.0, 10.0),
            periodic: [true, false],
        },
        Container::Box {
            min: Point3::origin(),
            max: Point3::new(26.0, 10.0, 10.0),
            periodic: [true, true],
        },
        Container::Box {
            min: Point3::origin(),
            max: Point3::new(50.0, 10.0, 10.0),
            periodic: [false, true],
        },
        Container::Cylinder {
            base: Point3::new(1.0, -2.0, 0.5),
            radius: 18.0,
            height: 12.0,
        },
    ];
    let mut digests = Vec::new();
    for c in &boxes {
        assert!(slabs::slab_count(c, 2.0, 4) >= 2, "{c:?} is not slabbed");
        let run = |threads: usize, params: Pack3Params| {
            let pool = rayon::ThreadPoolBuilder::new()
                .num_threads(threads)
                .build()
                .expect("pool");
            pool.install(|| pack3d_seeded(c, &uniform(), &params, 3).expect("pack"))
        };
        let p1 = run(1, params);
        let p2 = run(2, params);
        assert_eq!(
            (p1.spheres.len(), digest(&p1)),
            (p2.spheres.len(), digest(&p2)),
            "{c:?}: thread count changed the packing"
        );
        digests.push((p1.spheres.len(), digest(&p1)));
        let worst = brute_worst(c, &p1.spheres);
        assert!(worst >= -1e-9, "{c:?}: worst gap {worst}");
        let seq = run(2, Pack3Params { slabs: 0, ..params });
        let (f_slab, f_seq) = (
            solid_fraction(c, &p1.spheres).expect("fraction"),
            solid_fraction(c, &seq.spheres).expect("fraction"),
        );
        assert!(
            f_slab > f_seq - 0.01,
            "{c:?}: slabs {f_slab:.4} against sequential {f_seq:.4}"
        );
    }
    println!("slab golden {digests:x?}");
    assert_eq!(digests[0], SLAB_GOLDEN);
    let prism = Container::mesh(prism_mesh(16, 40.0, 20.0)).expect("prism");
    assert_eq!(
        slabs::slab_count(&prism, 2.0, 4),
        1,
        "meshes pack sequentially"
    );
}

const SLAB_GOLDEN: (usize, u64) = (0x54d, 0x2734_71a7_d6dc_661a);
