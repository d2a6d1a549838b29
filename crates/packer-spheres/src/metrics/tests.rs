//! Oracles of the 3D packing metrics: closed-form volumes (sphere, cap,
//! quarter and eighth, Viviani's window, sphere ∩ infinite cylinder),
//! additivity, the simple cubic lattice, periodic images, and a brute-force
//! O(n²) pair check; the log-normal grading against known normal quantiles.

use super::*;
use approx::{assert_abs_diff_eq, assert_relative_eq};
use nalgebra::{Point3, Vector3};
use packer_quadtree::{erfc, norm_cdf, norm_ppf};
use proptest::prelude::*;
use rand::{Rng, SeedableRng};

fn sphere(x: f64, y: f64, z: f64, r: f64) -> Sphere {
    Sphere {
        center: Point3::new(x, y, z),
        radius: r,
    }
}

fn cap(r: f64, h: f64) -> f64 {
    PI * h * h * (3.0 * r - h) / 3.0
}

/// The box `[0, 2]³` as a closed outward mesh.
fn box_mesh() -> levelset::TriMesh {
    let v: Vec<Point3<f64>> = (0..8)
        .map(|c| {
            Point3::new(
                2.0 * f64::from(c & 1),
                2.0 * f64::from((c >> 1) & 1),
                2.0 * f64::from((c >> 2) & 1),
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
    levelset::TriMesh::new(v, t).expect("box mesh")
}

// ---------------------------------------------------------------------------
// Exact volumes
// ---------------------------------------------------------------------------

#[test]
fn one_sphere_inside_counts_whole() {
    let c = Container::walled_box(Vector3::new(10.0, 10.0, 10.0));
    let s = [sphere(5.0, 4.0, 6.0, 1.5)];
    let v = sphere_volume(1.5);
    assert_relative_eq!(
        solid_fraction(&c, &s).expect("valid"),
        v / 1000.0,
        max_relative = 1e-14
    );
    let core = core_solid_fraction(&c, &s, 1.0).expect("valid");
    assert_relative_eq!(core.core_volume, 512.0, max_relative = 1e-14);
    assert_relative_eq!(core.fraction, v / 512.0, max_relative = 1e-14);
    assert_eq!(core.n_spheres_touching, 1);
    let cyl = Container::Cylinder {
        base: Point3::new(5.0, 5.0, 0.0),
        radius: 4.0,
        height: 10.0,
    };
    let core = core_solid_fraction(&cyl, &s, 0.5).expect("valid");
    assert_relative_eq!(core.core_volume, PI * 12.25 * 9.0, max_relative = 1e-14);
    assert_relative_eq!(core.fraction * core.core_volume, v, max_relative = 1e-14);
}

#[test]
fn box_face_cuts_a_spherical_cap() {
    // Core of [0, 10]³ with margin 1 starts at z = 1; the sphere sticks
    // out below it by h.
    let c = Container::walled_box(Vector3::new(10.0, 10.0, 10.0));
    let r = 1.3;
    for h in [1e-6, 0.01, 0.3, 1.0, 1.3, 2.0, 2.6 - 1e-9] {
        let s = [sphere(5.0, 5.0, 1.0 + r - h, r)];
        let core = core_solid_fraction(&c, &s, 1.0).expect("valid");
        let inside = core.fraction * core.core_volume;
        assert_relative_eq!(
            inside,
            cap(r, 2.0 * r - h),
            epsilon = 1e-15,
            max_relative = 1e-12
        );
    }
    // Cut by a side face (x) instead: same caps through the slice areas.
    for h in [0.05, 0.7, 1.3, 2.1] {
        let s = sphere(1.0 + r - h, 5.0, 5.0, r);
        let v = sphere_box_volume(&s, [1.0; 3], [9.0; 3]);
        assert_relative_eq!(v, cap(r, 2.0 * r - h), max_relative = 1e-12);
    }
}

#[test]
fn edges_and_corners_give_quarters_and_eighths() {
    let r = 0.8;
    let v = sphere_volume(r);
    let lo = [0.0; 3];
    let hi = [5.0; 3];
    assert_relative_eq!(
        sphere_box_volume(&sphere(0.0, 0.0, 2.0, r), lo, hi),
        v / 4.0,
        max_relative = 1e-13
    );
    assert_relative_eq!(
        sphere_box_volume(&sphere(2.0, 0.0, 0.0, r), lo, hi),
        v / 4.0,
        max_relative = 1e-13
    );
    assert_relative_eq!(
        sphere_box_volume(&sphere(0.0, 0.0, 0.0, r), lo, hi),
        v / 8.0,
        max_relative = 1e-13
    );
    // Infinite (periodic) sides: only z cuts.
    let inf = f64::INFINITY;
    assert_relative_eq!(
        sphere_box_volume(
            &sphere(0.0, 0.0, 0.0, r),
            [-inf, -inf, 0.0],
            [inf, inf, 1.0]
        ),
        v / 2.0,
        max_relative = 1e-13
    );
}

#[test]
fn box_pieces_tile_the_sphere() {
    // Two cuts per axis split space into 27 boxes; their volumes must add
    // up to the sphere whatever the cuts (edges, corners, near tangencies).
    let seed = 7;
    println!("seed {seed}");
    let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(seed);
    let inf = f64::INFINITY;
    for _ in 0..40 {
        let r = rng.random_range(0.5..2.0);
        let s = sphere(0.0, 0.0, 0.0, r);
        let mut cuts = [[0.0; 4]; 3];
        for c in &mut cuts {
            let mut a = rng.random_range(-1.2 * r..1.2 * r);
            let mut b = rng.random_range(-1.2 * r..1.2 * r);
            if a > b {
                std::mem::swap(&mut a, &mut b);
            }
            *c = [-inf, a, b, inf];
        }
        let mut total = 0.0;
        for i in 0..3 {
            for j in 0..3 {
                for k in 0..3 {
                    let lo = [cuts[0][i], cuts[1][j], cuts[2][k]];
                    let hi = [cuts[0][i + 1], cuts[1][j + 1], cuts[2][k + 1]];
                    total += sphere_box_volume(&s, lo, hi);
                }
            }
        }
        assert_relative_eq!(total, sphere_volume(r), max_relative = 1e-12);
    }
}

#[test]
fn sphere_centred_on_the_cylinder_wall_is_vivianis_window() {
    // Sphere of radius a centred on the wall of a cylinder of radius a/2:
    // V = (2/3)(π − 4/3) a³ (Viviani's window).
    let a = 2.0;
    let cyl = Container::Cylinder {
        base: Point3::new(1.0, -3.0, 0.0),
        radius: 0.5 * a,
        height: 10.0,
    };
    let s = [sphere(1.0 + 0.5 * a, -3.0, 5.0, a)];
    let core = core_solid_fraction(&cyl, &s, 0.0).expect("valid");
    let expect = 2.0 / 3.0 * (PI - 4.0 / 3.0) * a * a * a;
    assert_relative_eq!(
        core.fraction * core.core_volume,
        expect,
        max_relative = 1e-11
    );
    // Centred on the axis and larger than the cylinder:
    // V = 4/3 π (r³ − (r² − R²)^{3/2}).
    let (r, big) = (1.5, 1.0);
    let v = sphere_cylinder_volume(&sphere(0.0, 0.0, 0.0, r), 0.0, 0.0, big, -5.0, 5.0);
    let expect = 4.0 / 3.0 * PI * (r * r * r - (r * r - big * big).powf(1.5));
    assert_relative_eq!(v, expect, max_relative = 1e-12);
    // A small sphere on the wall: a bit less than half (the wall is convex).
    let v = sphere_cylinder_volume(&sphere(10.0, 0.0, 0.0, 0.1), 0.0, 0.0, 10.0, -1.0, 1.0);
    let half = 0.5 * sphere_volume(0.1);
    assert!(v < half && v > 0.99 * half, "{v} vs {half}");
}

#[test]
fn lens_and_rectangle_areas_are_exact() {
    // Two unit circles one radius apart: 2π/3 − √3/2.
    assert_relative_eq!(
        lens_area(1.0, 1.0, 1.0),
        2.0 * PI / 3.0 - 3f64.sqrt() / 2.0,
        max_relative = 1e-14
    );
    assert_relative_eq!(lens_area(0.5, 0.2, 2.0), PI * 0.25, max_relative = 1e-15);
    assert_abs_diff_eq!(lens_area(0.5, 2.6, 2.0), 0.0);
    // Circular segment beyond x = 0.5: r² acos(h/r) − h √(r² − h²).
    let seg = 0.5f64.acos() - 0.5 * 0.75f64.sqrt();
    assert_relative_eq!(
        rect_area(1.0, 0.5, 9.0, -9.0, 9.0),
        seg,
        max_relative = 1e-14
    );
    let s = 0.5f64.sqrt();
    assert_relative_eq!(rect_area(1.0, -s, s, -s, s), 2.0, max_relative = 1e-14);
    assert_relative_eq!(
        rect_area(1.0, 0.0, f64::INFINITY, f64::NEG_INFINITY, 0.0),
        PI / 4.0,
        max_relative = 1e-14
    );
}

/// Volume of a sphere (centre inside a convex cross-section, all of its
/// height inside the region) by an independent formulation: in polar
/// coordinates about the centre, `V = ∫ 2/3 (r³ − (r² − ρ_max(θ)²)^{3/2}) dθ`
/// with `ρ_max(θ)` the smaller of `r` and the ray length to the boundary;
/// trapezoid rule in θ (periodic, kinks only where `ρ_max = r`).
fn polar_volume(r: f64, ray: impl Fn(f64) -> f64) -> f64 {
    let n = 200_000;
    let h = 2.0 * PI / f64::from(n);
    (0..n)
        .map(|k| {
            let m = ray(f64::from(k) * h).min(r);
            2.0 / 3.0 * (r * r * r - (r * r - m * m).max(0.0).powf(1.5))
        })
        .sum::<f64>()
        * h
}

#[test]
fn slice_integration_matches_polar_quadrature() {
    let seed = 21;
    println!("seed {seed}");
    let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(seed);
    for _ in 0..12 {
        let r = rng.random_range(0.3..1.5);
        // Cylinder of radius 1 about the origin, sphere centre inside.
        let d = rng.random_range(0.0..0.999);
        let s = sphere(d, 0.0, 0.0, r);
        let v = sphere_cylinder_volume(&s, 0.0, 0.0, 1.0, -5.0, 5.0);
        // Ray from (d, 0) at angle θ to the unit circle.
        let expect = polar_volume(r, |t: f64| {
            let (c, sn) = (t.cos(), t.sin());
            -d * c + (1.0 - d * d * sn * sn).sqrt()
        });
        assert_relative_eq!(v, expect, max_relative = 1e-9);
        // Rectangle [0, 1] × [0, 0.7], centre inside.
        let (cx, cy) = (rng.random_range(0.0..1.0), rng.random_range(0.0..0.7));
        let s = sphere(cx, cy, 0.0, r);
        let v = sphere_box_volume(&s, [0.0, 0.0, -5.0], [1.0, 0.7, 5.0]);
        let expect = polar_volume(r, |t: f64| {
            let (c, sn) = (t.cos(), t.sin());
            let tx = if c > 0.0 {
                (1.0 - cx) / c
            } else if c < 0.0 {
                -cx / c
            } else {
                f64::INFINITY
            };
            let ty = if sn > 0.0 {
                (0.7 - cy) / sn
            } else if sn < 0.0 {
                -cy / sn
            } else {
                f64::INFINITY
            };
            tx.min(ty)
        });
        assert_relative_eq!(v, expect, max_relative = 1e-9);
    }
}

#[test]
fn simple_cubic_lattice() {
    // k³ touching spheres of diameter d filling [0, k d]³.
    let (k, d) = (6usize, 1.0);
    let mut spheres = Vec::new();
    for i in 0..k {
        for j in 0..k {
            for l in 0..k {
                let p = |v: usize| (v as f64 + 0.5) * d;
                spheres.push(sphere(p(i), p(j), p(l), 0.5 * d));
            }
        }
    }
    let side = k as f64 * d;
    let c = Container::walled_box(Vector3::new(side, side, side));
    assert_relative_eq!(
        solid_fraction(&c, &spheres).expect("valid"),
        PI / 6.0,
        max_relative = 1e-13
    );
    // Core boundaries through the cell faces or through the centres of
    // the outer layer: π/6 exactly.
    for margin in [0.0, 0.5 * d, d, 1.5 * d] {
        let core = core_solid_fraction(&c, &spheres, margin).expect("valid");
        assert_relative_eq!(core.fraction, PI / 6.0, max_relative = 1e-12);
    }
    let rep = check_spheres(&c, &spheres, 1e-9).expect("valid");
    assert!(rep.is_clean(1e-12), "{rep:?}");
    assert_abs_diff_eq!(rep.worst_pair_gap, 0.0, epsilon = 1e-12);
    assert_abs_diff_eq!(rep.worst_wall_gap, 0.0, epsilon = 1e-12);
    let kf = k as f64;
    assert_eq!(rep.pair_contacts, 3 * k * k * (k - 1));
    assert_relative_eq!(
        rep.coordination_number,
        6.0 * (kf - 1.0) / kf,
        max_relative = 1e-14
    );
    assert_eq!(rep.wall_contacts, k * k * k - (k - 2) * (k - 2) * (k - 2));
    // Periodic in x and y: four more contacts per sphere through the
    // faces; z stays walled. Interior spheres have 6.
    let per = Container::Box {
        min: Point3::origin(),
        max: Point3::new(side, side, side),
        periodic: [true, true],
    };
    let rep = check_spheres(&per, &spheres, 1e-9).expect("valid");
    assert_eq!(rep.pair_contacts, 2 * k * k * k + k * k * (k - 1));
    assert_relative_eq!(
        rep.coordination_number,
        4.0 + 2.0 * (kf - 1.0) / kf,
        max_relative = 1e-14
    );
    assert_eq!(rep.wall_contacts, 2 * k * k);
    let core = core_solid_fraction(&per, &spheres, 0.5 * d).expect("valid");
    assert_relative_eq!(core.fraction, PI / 6.0, max_relative = 1e-12);
    assert_relative_eq!(
        core.core_volume,
        side * side * (side - d),
        max_relative = 1e-14
    );
}

// ---------------------------------------------------------------------------
// Overlap checker
// ---------------------------------------------------------------------------

#[test]
fn overlapping_pair_has_the_right_gap() {
    let c = Container::walled_box(Vector3::new(10.0, 10.0, 10.0));
    let s = [
        sphere(2.0, 2.0, 2.0, 1.0),
        sphere(7.0, 7.0, 7.0, 0.5),
        sphere(2.0, 3.9, 2.0, 1.0),
        sphere(7.0, 7.0, 8.2, 0.7),
    ];
    let rep = check_spheres(&c, &s, 1e-9).expect("valid");
    assert_relative_eq!(rep.worst_pair_gap, -0.1, max_relative = 1e-12);
    assert_eq!(rep.worst_pair, Some((0, 2)));
    // Normalised: 0.1 / 2 against 0.0 / 1.0 (pair 1–3 is touching).
    assert_relative_eq!(rep.worst_normalised_gap, -0.05, max_relative = 1e-12);
    assert_eq!(rep.worst_normalised_pair, Some((0, 2)));
    assert_eq!(rep.pair_contacts, 1);
    assert_relative_eq!(rep.coordination_number, 0.5);
    assert!(!rep.is_clean(1e-9));
    assert!(rep.is_clean(0.06));
    // Walls: spheres 0 and 2 are 1 from the x and z faces (tie: 0).
    assert_relative_eq!(rep.worst_wall_gap, 1.0, max_relative = 1e-12);
    assert_eq!(rep.worst_wall_sphere, Some(0));
}

#[test]
fn periodic_images_cross_periodic_faces_only() {
    let c = Container::Box {
        min: Point3::new(0.0, 0.0, 0.0),
        max: Point3::new(10.0, 10.0, 10.0),
        periodic: [true, false],
    };
    // Across x (periodic): distance 0.9 through the face, radii 0.5.
    let s = [sphere(0.4, 5.0, 5.0, 0.5), sphere(9.5, 5.0, 5.0, 0.5)];
    let rep = check_spheres(&c, &s, 1e-9).expect("valid");
    assert_relative_eq!(rep.worst_pair_gap, -0.1, max_relative = 1e-10);
    assert_eq!(rep.worst_pair, Some((0, 1)));
    // Sphere 0 crosses the periodic face: not a wall protrusion.
    assert_relative_eq!(rep.worst_wall_gap, 4.5, max_relative = 1e-12);
    // Same across y (walled): no pair within reach, both spheres 0.1
    // from the walls.
    let s = [sphere(5.0, 0.6, 5.0, 0.5), sphere(5.0, 9.4, 5.0, 0.5)];
    let rep = check_spheres(&c, &s, 1e-9).expect("valid");
    assert_eq!(rep.worst_pair, None);
    assert!(rep.worst_pair_gap.is_infinite());
    assert_relative_eq!(rep.worst_wall_gap, 0.1, max_relative = 1e-10);
    assert!(rep.is_clean(1e-9));
    // A sphere protruding through the walled y face.
    let s = [sphere(5.0, 0.3, 5.0, 0.5)];
    let rep = check_spheres(&c, &s, 1e-9).expect("valid");
    assert_relative_eq!(rep.worst_wall_gap, -0.2, max_relative = 1e-12);
    assert!(!rep.is_clean(1e-9));
    // Only two cells per period (length 3 for d = 1): still one image.
    let c2 = Container::Box {
        min: Point3::origin(),
        max: Point3::new(3.0, 3.0, 3.0),
        periodic: [true, true],
    };
    let s = [sphere(0.2, 1.5, 1.5, 0.5), sphere(2.5, 1.5, 1.5, 0.5)];
    let rep = check_spheres(&c2, &s, 1e-9).expect("valid");
    assert_relative_eq!(rep.worst_pair_gap, -0.3, max_relative = 1e-12);
}

#[test]
fn cylinder_and_mesh_walls() {
    let cyl = Container::Cylinder {
        base: Point3::new(1.0, 1.0, 0.0),
        radius: 2.0,
        height: 4.0,
    };
    let s = [sphere(2.5, 1.0, 2.0, 0.4), sphere(1.0, 1.0, 3.8, 0.3)];
    let rep = check_spheres(&cyl, &s, 1e-9).expect("valid");
    assert_relative_eq!(rep.worst_wall_gap, -0.1, max_relative = 1e-12);
    assert_eq!(rep.worst_wall_sphere, Some(1));
    assert_relative_eq!(
        rep.worst_normalised_wall_gap,
        -0.1 / 0.6,
        max_relative = 1e-12
    );
    // The mesh of the box [0, 2]³ behaves as the walled box.
    let mesh = Container::mesh(box_mesh()).expect("closed");
    let boxed = Container::walled_box(Vector3::new(2.0, 2.0, 2.0));
    let s = [
        sphere(1.0, 1.0, 1.0, 0.3),
        sphere(0.35, 1.2, 1.7, 0.3),
        sphere(1.9, 0.1, 0.2, 0.25),
    ];
    let a = check_spheres(&mesh, &s, 1e-9).expect("valid");
    let b = check_spheres(&boxed, &s, 1e-9).expect("valid");
    assert_relative_eq!(a.worst_wall_gap, b.worst_wall_gap, epsilon = 1e-12);
    assert_eq!(a.worst_wall_sphere, b.worst_wall_sphere);
    assert_relative_eq!(a.worst_wall_gap, -0.15, epsilon = 1e-12);
    // Outside a corner the mesh distance is Euclidean (negative).
    let walls = Walls::new(&mesh).expect("mesh");
    assert_relative_eq!(
        walls.clearance([3.0, 3.0, 1.0]),
        -(2f64.sqrt()),
        epsilon = 1e-12
    );
    assert_relative_eq!(walls.clearance([0.5, 1.0, 1.0]), 0.5, epsilon = 1e-12);
}

#[test]
fn mesh_core_is_a_close_voxel_estimate() {
    // A jittered 5³ lattice of spheres in the box [0, 2]³ as a mesh against
    // the exact box computation. Single spheres are resolved to a few per
    // cent by the d_min/8 lattice; over many spheres the errors average out.
    let seed = 13;
    println!("seed {seed}");
    let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(seed);
    let mut s = Vec::new();
    for i in 0..5 {
        for j in 0..5 {
            for k in 0..5 {
                let p = |v: i32| 0.2 + 0.4 * f64::from(v);
                let mut jit = || rng.random_range(-0.04..0.04);
                s.push(sphere(
                    p(i) + jit(),
                    p(j) + jit(),
                    p(k) + jit(),
                    rng.random_range(0.1..0.15),
                ));
            }
        }
    }
    let mesh = Container::mesh(box_mesh()).expect("closed");
    let boxed = Container::walled_box(Vector3::new(2.0, 2.0, 2.0));
    let exact = core_solid_fraction(&boxed, &s, 0.3).expect("valid");
    let est = core_solid_fraction(&mesh, &s, 0.3).expect("valid");
    assert_relative_eq!(est.core_volume, exact.core_volume, max_relative = 1e-3);
    assert_relative_eq!(est.fraction, exact.fraction, max_relative = 0.01);
    // Spheres only grazing the core may hold no sample.
    assert!(est.n_spheres_touching <= exact.n_spheres_touching);
    // The core [0.4, 1.6]³ holds the inner 3³ spheres whole (they reach
    // 0.41–1.59) and no other.
    let exact = core_solid_fraction(&boxed, &s, 0.4).expect("valid");
    let est = core_solid_fraction(&mesh, &s, 0.4).expect("valid");
    assert_eq!(exact.n_spheres_touching, 27);
    assert_eq!(est.n_spheres_touching, 27);
    assert_relative_eq!(est.fraction, exact.fraction, max_relative = 0.01);
    // Margin zero: the whole container.
    let exact = core_solid_fraction(&boxed, &s, 0.0).expect("valid");
    let est = core_solid_fraction(&mesh, &s, 0.0).expect("valid");
    assert_relative_eq!(est.core_volume, 8.0, max_relative = 1e-3);
    assert_relative_eq!(est.fraction, exact.fraction, max_relative = 0.01);
}

#[test]
fn bad_input_is_an_error() {
    let c = Container::walled_box(Vector3::new(2.0, 2.0, 2.0));
    let ok = [sphere(1.0, 1.0, 1.0, 0.5)];
    let bad = [sphere(1.0, f64::NAN, 1.0, 0.5)];
    let neg = [sphere(1.0, 1.0, 1.0, -0.5)];
    assert!(check_spheres(&c, &bad, 1e-9).is_err());
    assert!(check_spheres(&c, &neg, 1e-9).is_err());
    assert!(check_spheres(&c, &ok, -1.0).is_err());
    assert!(check_spheres(&c, &ok, f64::NAN).is_err());
    assert!(solid_fraction(&c, &neg).is_err());
    assert!(matches!(
        core_solid_fraction(&c, &ok, 1.0),
        Err(Error::EmptyCore { .. })
    ));
    assert!(core_solid_fraction(&c, &ok, -0.1).is_err());
    assert!(matches!(
        radial_profile(&c, &ok, 4),
        Err(Error::WrongContainer { .. })
    ));
    let cyl = Container::triaxial(2.0);
    assert!(matches!(
        radial_profile(&cyl, &ok, 0),
        Err(Error::Parameter { .. })
    ));
    assert!(matches!(
        core_solid_fraction(&cyl, &ok, 1.0),
        Err(Error::EmptyCore { .. })
    ));
    let thin = Container::Box {
        min: Point3::origin(),
        max: Point3::new(0.8, 2.0, 2.0),
        periodic: [true, false],
    };
    assert!(check_spheres(&thin, &ok, 1e-9).is_err());
    assert!(matches!(
        grading_report(&Grading::Constant { diameter: 1.0 }, &[]),
        Err(Error::Empty { .. })
    ));
    let empty = check_spheres(&c, &[], 1e-9).expect("valid");
    assert!(empty.is_clean(0.0) && empty.worst_pair.is_none());
}

/// Brute force over all pairs with the checker's gap formula.
fn brute(
    spheres: &[Sphere],
    len: [f64; 2],
    periodic: [bool; 2],
    reach: f64,
    tol: f64,
) -> (Worst, Worst, usize) {
    let (mut w, mut wn, mut contacts) = (Worst::NONE, Worst::NONE, 0);
    for i in 0..spheres.len() {
        for j in i + 1..spheres.len() {
            let (a, b) = (&spheres[i], &spheres[j]);
            let dx = min_image(b.center.x - a.center.x, len[0], periodic[0]);
            let dy = min_image(b.center.y - a.center.y, len[1], periodic[1]);
            let dz = b.center.z - a.center.z;
            let gap = (dx * dx + dy * dy + dz * dz).sqrt() - a.radius - b.radius;
            let d = 2.0 * a.radius.min(b.radius);
            if gap < reach {
                w.offer(gap, (i, j));
                wn.offer(gap / d, (i, j));
            }
            if gap.abs() <= tol * d {
                contacts += 1;
            }
        }
    }
    (w, wn, contacts)
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(64))]
    #[test]
    fn grid_checker_agrees_with_brute_force(
        raw in prop::collection::vec((0.0..1.0f64, 0.0..1.0f64, 0.0..1.0f64, 0.05..0.6f64), 0..80),
        px in any::<bool>(),
        py in any::<bool>(),
        scale in 2.0..8.0f64,
        tol in 0.0..0.5f64,
    ) {
        let (lx, ly, lz) = (scale, 1.3 * scale, 0.8 * scale);
        // Some centres outside the box in periodic directions (unwrapped).
        let spheres: Vec<Sphere> = raw
            .iter()
            .map(|&(x, y, z, r)| sphere(1.4 * x * lx - 0.2 * lx, y * ly, z * lz, r))
            .collect();
        let c = Container::Box {
            min: Point3::origin(),
            max: Point3::new(lx, ly, lz),
            periodic: [px, py],
        };
        let rep = check_spheres(&c, &spheres, tol).expect("valid");
        let (w, wn, contacts) = brute(&spheres, [lx, ly], [px, py], rep.pair_reach, tol);
        prop_assert_eq!(rep.worst_pair_gap.to_bits(), w.value.to_bits());
        prop_assert_eq!(rep.worst_pair, w.pair());
        prop_assert_eq!(rep.worst_normalised_gap.to_bits(), wn.value.to_bits());
        prop_assert_eq!(rep.worst_normalised_pair, wn.pair());
        prop_assert_eq!(rep.pair_contacts, contacts);
    }
}

#[test]
fn reports_do_not_depend_on_the_thread_count() {
    let seed = 3;
    println!("seed {seed}");
    let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(seed);
    let spheres: Vec<Sphere> = (0..20_000)
        .map(|_| {
            sphere(
                rng.random_range(0.0..30.0),
                rng.random_range(0.0..30.0),
                rng.random_range(0.0..30.0),
                rng.random_range(0.2..0.5),
            )
        })
        .collect();
    let c = Container::Box {
        min: Point3::origin(),
        max: Point3::new(30.0, 30.0, 30.0),
        periodic: [true, false],
    };
    let cyl = Container::Cylinder {
        base: Point3::new(15.0, 15.0, 0.0),
        radius: 15.0,
        height: 30.0,
    };
    let run = |threads: usize| {
        let pool = rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .build()
            .expect("pool");
        pool.install(|| {
            (
                check_spheres(&c, &spheres, 1e-3).expect("valid"),
                core_solid_fraction(&c, &spheres, 2.0).expect("valid"),
                radial_profile(&cyl, &spheres, 7).expect("valid"),
                solid_fraction(&c, &spheres).expect("valid"),
            )
        })
    };
    let (a, b) = (run(1), run(3));
    assert_eq!(a.0, b.0);
    assert_eq!(a.1.fraction.to_bits(), b.1.fraction.to_bits());
    assert_eq!(a.1.n_spheres_touching, b.1.n_spheres_touching);
    assert_eq!(a.2, b.2);
    assert_eq!(a.3.to_bits(), b.3.to_bits());
}

// ---------------------------------------------------------------------------
// Radial profile
// ---------------------------------------------------------------------------

#[test]
fn radial_profile_sums_to_the_sphere_volume() {
    let cyl = Container::Cylinder {
        base: Point3::new(0.0, 0.0, 0.0),
        radius: 3.0,
        height: 6.0,
    };
    for (s, n_bins) in [
        (sphere(0.0, 0.0, 3.0, 1.0), 7),
        (sphere(1.1, -0.7, 2.0, 0.9), 10),
        (sphere(0.3, 0.0, 4.0, 0.25), 1),
    ] {
        let prof = radial_profile(&cyl, &[s], n_bins).expect("valid");
        assert_eq!(prof.len(), n_bins);
        let total: f64 = prof
            .iter()
            .map(|b| b.solid_fraction * PI * (b.r_outer.powi(2) - b.r_inner.powi(2)) * 6.0)
            .sum();
        assert_relative_eq!(total, sphere_volume(s.radius), max_relative = 1e-12);
        assert_relative_eq!(prof[n_bins - 1].r_outer, 3.0);
    }
    // On the axis: the shell [a, b] of a unit sphere holds
    // V(b) − V(a), V(R) = 4/3 π (1 − (1 − R²)^{3/2}).
    let prof = radial_profile(&cyl, &[sphere(0.0, 0.0, 3.0, 1.0)], 6).expect("valid");
    let v = |big: f64| 4.0 / 3.0 * PI * (1.0 - (1.0 - big.min(1.0).powi(2)).powf(1.5));
    for b in &prof {
        let shell = PI * (b.r_outer.powi(2) - b.r_inner.powi(2)) * 6.0;
        assert_relative_eq!(
            b.solid_fraction * shell,
            v(b.r_outer) - v(b.r_inner),
            epsilon = 1e-13
        );
    }
}

// ---------------------------------------------------------------------------
// Grading
// ---------------------------------------------------------------------------

#[test]
fn erfc_and_normal_quantiles_match_reference_values() {
    // Reference values: Python's math.erfc and statistics.NormalDist.
    for (x, e) in [
        (0.0, 1.0),
        (0.5, 0.479_500_122_186_953_5),
        (1.0, 0.157_299_207_050_285_13),
        (1.5, 0.033_894_853_524_689_27),
        (2.0, 0.004_677_734_981_047_265),
        (3.0, 2.209_049_699_858_544e-5),
        (5.0, 1.537_459_794_428_035e-12),
        (10.0, 2.088_487_583_762_545e-45),
        (-1.0, 1.842_700_792_949_715),
    ] {
        assert_relative_eq!(erfc(x), e, max_relative = 3e-15);
    }
    for (p, z) in [
        (0.5, 0.0_f64),
        (0.975, 1.959_963_984_540_054),
        (0.841_344_746_068_542_9, 1.0),
        (0.02, -2.053_748_910_631_822_5),
        (1e-10, -6.361_340_902_404_056),
        (1e-300, -37.047_096_299_361_2),
    ] {
        assert_abs_diff_eq!(norm_ppf(p), z, epsilon = 1e-13 * z.abs().max(1.0));
    }
    for k in 1..200 {
        let p = f64::from(k) / 200.0;
        assert_relative_eq!(norm_cdf(norm_ppf(p)), p, max_relative = 1e-14);
        let q = 10f64.powi(-k);
        if q > 1e-300 {
            assert_relative_eq!(norm_cdf(norm_ppf(q)), q, max_relative = 1e-12);
        }
    }
}

#[test]
fn lognormal_quantiles_and_truncation() {
    let (median, sigma) = (2.0, 0.4);
    // Practically untruncated: the quantiles of the log-normal.
    let g = Grading::LogNormal {
        median,
        sigma,
        min: median * (-12.0 * sigma).exp(),
        max: median * (12.0 * sigma).exp(),
    };
    g.validate().expect("valid");
    assert_relative_eq!(g.diameter_at(0.5), median, max_relative = 1e-14);
    let p1 = norm_cdf(1.0);
    assert_relative_eq!(
        g.diameter_at(p1),
        median * sigma.exp(),
        max_relative = 1e-13
    );
    assert_relative_eq!(g.passing_at(median * sigma.exp()), p1, max_relative = 1e-14);
    // Truncated at the median: the new median is the 75 % quantile.
    let g = Grading::LogNormal {
        median,
        sigma,
        min: median,
        max: 10.0,
    };
    g.validate().expect("valid");
    let z75 = 0.674_489_750_196_081_7;
    let mass = norm_cdf(-(5f64.ln() / sigma));
    let z = norm_ppf(0.5 + 0.5 * (0.5 - mass));
    assert_relative_eq!(
        g.diameter_at(0.5),
        median * (sigma * z).exp(),
        max_relative = 1e-13
    );
    assert!((z - z75).abs() < 1e-3);
    assert_relative_eq!(g.diameter_at(0.0), median);
    assert_relative_eq!(g.diameter_at(1.0), 10.0);
    assert_relative_eq!(g.d_min(), median);
    assert_relative_eq!(g.d_max(), 10.0);
    assert_abs_diff_eq!(g.passing_at(1.0), 0.0);
    assert_abs_diff_eq!(g.passing_at(11.0), 1.0);
    for k in 0..=50 {
        let u = f64::from(k) / 50.0;
        assert_abs_diff_eq!(g.passing_at(g.diameter_at(u)), u, epsilon = 1e-12);
    }
    // Far in the upper tail (8–9 σ above the median): still monotone and
    // invertible thanks to the upper-tail formulation.
    let g = Grading::LogNormal {
        median: 1.0,
        sigma: 0.1,
        min: 0.8f64.exp(),
        max: 0.9f64.exp(),
    };
    g.validate().expect("valid");
    let mut last = 0.0;
    for k in 0..=20 {
        let u = f64::from(k) / 20.0;
        let d = g.diameter_at(u);
        assert!(d >= last, "not monotone at {u}");
        last = d;
        assert_abs_diff_eq!(g.passing_at(d), u, epsilon = 1e-9);
    }
    let seed = 5;
    println!("seed {seed}");
    let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(seed);
    for _ in 0..1000 {
        let d = g.sample(&mut rng);
        assert!((0.8f64.exp()..=0.9f64.exp()).contains(&d));
    }
    for bad in [
        Grading::LogNormal {
            median: 1.0,
            sigma: 0.0,
            min: 0.5,
            max: 2.0,
        },
        Grading::LogNormal {
            median: 1.0,
            sigma: 0.2,
            min: 2.0,
            max: 1.0,
        },
        Grading::LogNormal {
            median: 1.0,
            sigma: 0.01,
            min: 1e6,
            max: 1e7,
        },
        Grading::LogNormal {
            median: f64::NAN,
            sigma: 0.2,
            min: 0.5,
            max: 1.0,
        },
    ] {
        assert!(bad.validate().is_err(), "{bad:?} accepted");
    }
}

#[test]
fn grading_report_of_a_uniform_sample() {
    // Uniform[1, 2] by number: mass passing (d⁴ − 1)/15, so
    // D_x = (1 + 15 x)^{1/4}, Cu = (10 / 2.5)^{1/4} = √2,
    // Cc = 5.5^{1/2} / 25^{1/4}.
    let g = Grading::Uniform { min: 1.0, max: 2.0 };
    let seed = 9;
    println!("seed {seed}");
    let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(seed);
    let spheres: Vec<Sphere> = (0..100_000)
        .map(|_| sphere(0.0, 0.0, 0.0, 0.5 * g.sample(&mut rng)))
        .collect();
    let rep = grading_report(&g, &spheres).expect("valid");
    assert_eq!(rep.n_spheres, 100_000);
    let dx = |x: f64| (1.0 + 15.0 * x).powf(0.25);
    assert_relative_eq!(rep.requested.d10, dx(0.1), max_relative = 1e-8);
    assert_relative_eq!(rep.requested.d60, dx(0.6), max_relative = 1e-8);
    assert_relative_eq!(rep.requested.cu, 2f64.sqrt(), max_relative = 1e-8);
    assert_relative_eq!(
        rep.requested.cc,
        5.5f64.sqrt() / 25f64.powf(0.25),
        max_relative = 1e-8
    );
    assert_relative_eq!(rep.requested.d50_number, 1.5, max_relative = 1e-14);
    assert!(rep.max_deviation < 0.02, "{}", rep.max_deviation);
    assert!(
        (rep.packed.cu - 2f64.sqrt()).abs() < 0.01,
        "{}",
        rep.packed.cu
    );
    assert!((rep.packed.d50_number - 1.5).abs() < 0.01);
    assert_eq!(rep.sizes.len(), rep.packed_passing.len());
    assert_abs_diff_eq!(rep.requested_passing[0], 0.0);
    assert_abs_diff_eq!(*rep.packed_passing.last().expect("sizes"), 1.0);
    // A constant grading and a constant sample agree exactly.
    let c = Grading::Constant { diameter: 1.0 };
    let rep = grading_report(&c, &[sphere(0.0, 0.0, 0.0, 0.5); 10]).expect("valid");
    assert_abs_diff_eq!(rep.max_deviation, 0.0, epsilon = 1e-9);
    assert_relative_eq!(rep.packed.cu, 1.0);
    assert_relative_eq!(rep.requested.cu, 1.0);
    // Log-normal sample against its own distribution.
    let ln = Grading::LogNormal {
        median: 1.0,
        sigma: 0.3,
        min: 0.5,
        max: 2.5,
    };
    let spheres: Vec<Sphere> = (0..50_000)
        .map(|_| sphere(0.0, 0.0, 0.0, 0.5 * ln.sample(&mut rng)))
        .collect();
    let rep = grading_report(&ln, &spheres).expect("valid");
    assert!(rep.max_deviation < 0.02, "{}", rep.max_deviation);
    assert!((rep.packed.d50_number - ln.diameter_at(0.5)).abs() < 0.02);
}
